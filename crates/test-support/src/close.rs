//! Element-wise closeness of computed values to their references, with messages that name the
//! quantity and the element.

/// Asserts |got - want| <= tol (1 + |want|) element-wise (an absolute tolerance near 0, a
/// relative one above 1), for f32 results against f64 references; a NaN reference must meet
/// a NaN.
#[track_caller]
pub fn assert_close(what: &str, got: &[f32], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        if w.is_nan() {
            assert!(g.is_nan(), "{what}[{i}]: {g}, want NaN");
            continue;
        }
        let err = (f64::from(g) - w).abs();
        assert!(err <= tol * (1.0 + w.abs()), "{what}[{i}]: {g}, want {w} (error {err:e})");
    }
}

/// Asserts every element of `got` is finite and within tol x max|want| of `want` (a tolerance
/// relative to the largest reference: two backends' f32 results).
#[track_caller]
pub fn assert_close_scaled(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(0.0_f32, |m, w| m.max(w.abs())).max(1e-6);
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(g.is_finite(), "{what}[{i}] = {g}");
        assert!((g - w).abs() <= tol * scale, "{what}[{i}]: {g} against {w} (scale {scale})");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_values_pass() {
        assert_close("x", &[1.0, f32::NAN, 0.0], &[1.0 + 1e-7, f64::NAN, 1e-9], 1e-6);
        assert_close_scaled("y", &[100.0, 0.001], &[100.001, 0.0], 1e-4);
    }

    #[test]
    #[should_panic(expected = "x[1]")]
    fn a_far_value_names_its_element() {
        assert_close("x", &[1.0, 2.0], &[1.0, 2.1], 1e-3);
    }

    #[test]
    #[should_panic(expected = "want NaN")]
    fn a_nan_reference_wants_a_nan() {
        assert_close("x", &[1.0], &[f64::NAN], 1e-3);
    }

    #[test]
    #[should_panic(expected = "y[0] = inf")]
    fn an_infinite_value_fails_the_scaled_check() {
        assert_close_scaled("y", &[f32::INFINITY], &[1.0], 1.0);
    }
}
