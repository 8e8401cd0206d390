//! Light selection and multiple importance sampling helpers shared by every integrator.

use crate::light::Light;

/// Power heuristic with β = 2 (Veach 1997, "Vea97", §9.2.4): the weight of a strategy with pdf
/// `a` against one with pdf `b`.
#[inline]
pub fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// Where next-event estimation is done: the light set depends on it ([`LightSet::at`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vertex {
    /// On a surface: a BSDF, or a BSSRDF's incident point, whose direction sampling follows
    /// the cosine (or a lobe around it).
    Surface,
    /// Inside a medium, where directions follow the phase function.
    Medium,
}

/// The lights next-event estimation samples, chosen uniformly.
#[derive(Debug, Clone)]
pub struct LightSet {
    indices: Vec<usize>,
}

impl LightSet {
    /// The lights of `lights` that next-event estimation samples at `vertex`: every light but
    /// pencil beams; at a surface, also not a constant environment when other lights compete
    /// for the light samples. A constant environment's light sample is a uniform direction on
    /// the sphere, half of which lie below the surface, while the surface's own direction
    /// sampling (cosine-weighted) matches its integrand up to visibility: a light sample spent
    /// on it is one the other lights lose. So at surfaces it is then left to direction
    /// sampling alone, where it counts with weight 1 (its light pdf is 0 there), and the other
    /// lights get every light sample. pbrt-v4 leaves a uniform environment to direction
    /// sampling the same way (`UniformInfiniteLight::SampleLi` with `allowIncompletePDF`,
    /// §12.5.1). On a marble sphere under a quad light and a constant sky this cut the BSSRDF
    /// render's variance 2.7× (docs/curved-objects.md). Alone, the environment keeps its light
    /// samples: a BSSRDF gathers light at every probe point but continues the path from one,
    /// so on a small body under a uniform sky its light samples still help. In media the
    /// phase function is no better than the light's uniform sample, and the light sample's
    /// shadow ray reads the medium's transmittance, so the environment stays sampled there.
    pub fn at(lights: &[Light], vertex: Vertex) -> Self {
        let constant_sky = |l: &Light| matches!(l, Light::Environment(e) if e.map.is_none());
        let others = lights
            .iter()
            .any(|l| !matches!(l, Light::Beam(_)) && !constant_sky(l));
        Self {
            indices: (0..lights.len())
                .filter(|&i| match &lights[i] {
                    Light::Beam(_) => false,
                    l if constant_sky(l) => vertex == Vertex::Medium || !others,
                    _ => true,
                })
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

#[cfg(test)]
mod tests {
    use super::*;
    use bssrdf_core::Rgb;
    use glam::DVec3;

    /// A constant environment beside other lights is left to direction sampling at surfaces
    /// and sampled in media; alone it is sampled at both; every other light but a beam is
    /// sampled at both.
    #[test]
    fn surfaces_leave_a_constant_environment_to_direction_sampling() {
        let texture = crate::field::Texture::from_texels("sky.exr", 2, 1, vec![[1.0; 3]; 2])
            .expect("texture");
        let map = crate::light::EnvironmentMap::new(
            std::sync::Arc::new(texture),
            Rgb::ONE,
            crate::field::Axis::Z,
            0.0,
        )
        .expect("map");
        let lights = [
            Light::point(DVec3::Z, Rgb::ONE).expect("point"),
            Light::environment(Rgb::ONE).expect("environment"),
            Light::beam(DVec3::ZERO, DVec3::Z, Rgb::ONE).expect("beam"),
            Light::environment_map(map),
        ];
        let surface = LightSet::at(&lights, Vertex::Surface);
        let medium = LightSet::at(&lights, Vertex::Medium);
        assert_eq!(surface.indices, vec![0, 3]);
        assert_eq!(medium.indices, vec![0, 1, 3]);
        assert_eq!(surface.select_pdf(), 0.5);
        assert!(!surface.contains(1) && medium.contains(1));
        // Alone (beside a beam, which next-event estimation never samples), the constant
        // environment keeps its light samples at surfaces too.
        let alone = &lights[1..3];
        assert_eq!(LightSet::at(alone, Vertex::Surface).indices, vec![0]);
        assert_eq!(LightSet::at(alone, Vertex::Medium).indices, vec![0]);
    }
}
