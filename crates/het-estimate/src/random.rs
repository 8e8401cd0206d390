//! Random numbers: the caller-provided source of uniform numbers the estimators draw from, and
//! a small seeded generator for examples, tests and renderers without one of their own.

/// A stream of uniform numbers in `[0, 1)`, provided by the caller so that renders stay
/// deterministic for a given seed whatever the thread count.
pub trait UniformSource {
    /// The next uniform number in `[0, 1)`.
    fn next_f64(&mut self) -> f64;
}

impl<U: UniformSource + ?Sized> UniformSource for &mut U {
    fn next_f64(&mut self) -> f64 {
        (**self).next_f64()
    }
}

/// SplitMix64 (SLF14: Steele, Lea & Flood 2014): a tiny seeded [`UniformSource`] for
/// examples, tests and benchmarks, and for renderers without a stream of their own (a
/// renderer usually passes its own per-pixel stream, which keeps its renders deterministic
/// per seed). Not cryptographic.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A stream determined by `seed`.
    pub const fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

impl UniformSource for SplitMix64 {
    /// 53 random bits scaled into `[0, 1)`.
    #[inline]
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
