//! Light selection and multiple importance sampling helpers shared by every integrator.

use crate::light::Light;

/// Power heuristic with β = 2 (Veach 1997, "Vea97", §9.2.4): the weight of a strategy with pdf
/// `a` against one with pdf `b`.
#[inline]
pub fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// The lights next-event estimation samples (every light but pencil beams), chosen uniformly.
#[derive(Debug, Clone)]
pub struct LightSet {
    indices: Vec<usize>,
}

impl LightSet {
    /// The sampleable lights of `lights`.
    pub fn new(lights: &[Light]) -> Self {
        Self {
            indices: (0..lights.len())
                .filter(|&i| !matches!(lights[i], Light::Beam(_)))
                .collect(),
        }
    }
    /// True when there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
    /// Probability of choosing any one light.
    pub fn select_pdf(&self) -> f64 {
        1.0 / self.indices.len() as f64
    }
    /// Chooses a light with `u ∈ [0, 1)`; returns its index in the scene's light list.
    pub fn select(&self, u: f64) -> Option<usize> {
        let n = self.indices.len();
        (n > 0).then(|| self.indices[((u * n as f64) as usize).min(n - 1)])
    }
    /// True when light `i` is in the set.
    pub fn contains(&self, i: usize) -> bool {
        self.indices.contains(&i)
    }
}
