//! SplitMix64 (Steele, Lea and Flood 2014; the reference is Vigna's `splitmix64.c`): a small,
//! fast, well-mixed 64-bit generator. It is the seeded stream behind every reproducible draw of
//! the workspace that does not use `rand` — orbit cameras, sensor noise, light splits, the
//! Lanczos start block, Monte Carlo albedo estimates — so a given seed gives the same scene,
//! split and estimate on every machine. The mappings to floats below are part of that contract:
//! changing one changes generated scenes (and so every run id).

/// The SplitMix64 generator; `Clone` gives an independent copy of the stream.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator from a seed (any value, 0 included).
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [-1, 1) with 53 random bits.
    pub fn next_signed_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Uniform in [0, 1) with 24 random bits (every value exact in f32).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// An integer in `0..n` (`n > 0`) by reduction modulo `n`; its bias, below `n / 2^64`, is
    /// irrelevant for the small `n` it serves (shuffles of views and lights).
    pub fn next_below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// Shuffles `items` in place (Fisher–Yates from the back, one draw per position).
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            items.swap(i, self.next_below(i as u64 + 1) as usize);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_stream() {
        // splitmix64.c seeded with 1234567.
        let mut r = SplitMix64::new(1_234_567);
        let first: Vec<u64> = (0..5).map(|_| r.next_u64()).collect();
        assert_eq!(
            first,
            [
                6_457_827_717_110_365_317,
                3_203_168_211_198_807_973,
                9_817_491_932_198_370_423,
                4_593_380_528_125_082_431,
                16_408_922_859_458_223_821,
            ]
        );
    }

    #[test]
    fn floats_lie_in_their_ranges_and_use_the_top_bits() {
        let mut r = SplitMix64::new(7);
        for _ in 0..10_000 {
            let (a, b, c) = (r.next_f64(), r.next_signed_f64(), r.next_f32());
            assert!((0.0..1.0).contains(&a) && (-1.0..1.0).contains(&b) && (0.0..1.0).contains(&c));
        }
        let (mut x, mut y) = (SplitMix64::new(9), SplitMix64::new(9));
        let top = x.next_u64();
        assert_eq!(y.next_f32(), (top >> 40) as f32 / 16_777_216.0);
    }

    #[test]
    fn shuffle_is_a_seeded_permutation() {
        let shuffled = |seed| {
            let mut v: Vec<u32> = (0..50).collect();
            SplitMix64::new(seed).shuffle(&mut v);
            v
        };
        let a = shuffled(3);
        assert_eq!(a, shuffled(3));
        assert_ne!(a, shuffled(4));
        let mut sorted = a.clone();
        sorted.sort();
        assert_eq!(sorted, (0..50).collect::<Vec<_>>());
    }
}
