//! Probe sampling over a renderer's own hit record that is not `Copy` (it owns a `Vec`), and a
//! `ProbeChords` used as a trait object.

use het_estimate::bssrdf_core::{ProfileFamily, ProfileModel, Scattering};
use het_estimate::glam::DVec3;
use het_estimate::probe::{ProbeChords, ProbeSampler, probe};
use het_estimate::{Coefficients, FieldBounds, SplitMix64, SurfacePoint};

/// A hit record owning heap data, as a renderer's may (here the names of the layers at the
/// point).
#[derive(Clone, Debug)]
struct OwningHit {
    p: DVec3,
    layers: Vec<String>,
}

impl SurfacePoint for OwningHit {
    fn position(&self) -> DVec3 {
        self.p
    }
    fn normal(&self) -> DVec3 {
        DVec3::Z
    }
}

/// The plane z = 0.
struct Floor;

impl ProbeChords for Floor {
    type Point = OwningHit;
    fn for_each_hit(&self, o: DVec3, d: DVec3, t_max: f64, f: &mut dyn FnMut(&OwningHit)) {
        let t = -o.z / d.z;
        if (0.0..=t_max).contains(&t) {
            f(&OwningHit {
                p: o + t * d,
                layers: vec!["skin".into()],
            });
        }
    }
}

#[test]
fn probes_keep_non_copy_hits_and_accept_trait_objects() {
    let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.3).unwrap();
    let c = Coefficients::grey(0.01, 1.0);
    let sampler = ProbeSampler::new(family, FieldBounds::constant(c));
    let x_o = OwningHit {
        p: DVec3::ZERO,
        layers: Vec::new(),
    };
    let chords: &dyn ProbeChords<Point = OwningHit> = &Floor;
    let mut found = 0;
    for seed in 0..50 {
        let set = probe(&chords, &x_o, c, &sampler, &mut SplitMix64::new(seed));
        for h in set.iter() {
            assert_eq!(h.hit.layers, ["skin"]);
            assert!(h.weight > 0.0 && h.hit.p.z == 0.0);
            found += 1;
        }
    }
    // The normal-axis probe meets the plane on every draw.
    assert!(found >= 50, "{found} hits in 50 probe sets");
}
