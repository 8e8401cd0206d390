//! The caller-provided source of uniform random numbers.

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
