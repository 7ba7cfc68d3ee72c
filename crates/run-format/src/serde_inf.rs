//! Serde for an f64 that may be infinite (a PSNR of identical images): JSON has no infinity,
//! so non-finite values are written as the strings "inf", "-inf" and "nan" and read back from
//! them; finite values stay numbers.

use serde::{Deserialize, Deserializer, Serializer};

/// Writes `v`, non-finite values as strings.
pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else if v.is_nan() {
        s.serialize_str("nan")
    } else if *v > 0.0 {
        s.serialize_str("inf")
    } else {
        s.serialize_str("-inf")
    }
}

/// Reads a number or one of the strings "inf", "-inf", "nan".
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Repr {
        Number(f64),
        Text(String),
    }
    match Repr::deserialize(d)? {
        Repr::Number(v) => Ok(v),
        Repr::Text(t) => match t.as_str() {
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            "nan" => Ok(f64::NAN),
            other => Err(serde::de::Error::custom(format!("`{other}` is not a number"))),
        },
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct T {
        #[serde(with = "super")]
        v: f64,
    }

    #[test]
    fn infinities_round_trip_through_json() {
        for v in [1.5, f64::INFINITY, f64::NEG_INFINITY] {
            let text = serde_json::to_string(&T { v }).unwrap();
            assert_eq!(serde_json::from_str::<T>(&text).unwrap(), T { v }, "{text}");
        }
        assert_eq!(serde_json::to_string(&T { v: f64::INFINITY }).unwrap(), r#"{"v":"inf"}"#);
        assert!(serde_json::from_str::<T>(r#"{"v":"big"}"#).is_err());
    }
}
