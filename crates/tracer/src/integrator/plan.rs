//! How a method renders each translucent object: its BSSRDF or the path tracer, and with or
//! without the shape correction. One decision, read by the integrator that prepares the
//! render, by the warnings and by the sidecar.

use crate::integrator::{Coverage, Method};
use crate::optical_size::is_optically_small;
use crate::scene::Scene;

/// How one translucent object is rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct ObjectPlan {
    /// Path traced (the volumetric random walk inside it) rather than rendered by a BSSRDF.
    pub path_traced: bool,
    /// Its BSSRDF is scaled by the shape correction.
    pub corrected: bool,
    /// Too small for a half-space profile ([`is_optically_small`]).
    pub small: bool,
    /// Its medium scatters nowhere ([`is_clear`]): a clear absorbing dielectric, whose light
    /// is all refraction and absorption, which no BSSRDF profile describes.
    pub clear: bool,
}

/// Whether a translucent material's medium scatters nowhere (σs = 0 in every channel at every
/// point): glass, coloured liquids, a glTF volume with transmission but no scattering
/// extension (`docs/gltf.md`). A BSSRDF profile is light that scattered below the surface, so
/// for such a medium every profile is zero and a BSSRDF render shows it black; the path
/// tracer refracts through it and attenuates by Beer–Lambert (pbrt-v4 §11.2: a medium with
/// σs = 0 only absorbs).
pub fn is_clear(t: &crate::scene::Translucent) -> bool {
    t.medium.field_bounds().max.sigma_s.max_component() <= 0.0
}

/// The plan of every object of `scene` under `method`, by object index (`None` for objects
/// that are not translucent).
///
/// * `pt` path-traces every translucent object.
/// * A BSSRDF method renders each with its BSSRDF, except the objects the path tracer can walk
///   (a closed mesh, a medium defined in space or read through texture coordinates the mesh
///   has) that are clear ([`is_clear`]: no BSSRDF sees light in them, under every method), or,
///   under [`Coverage::HalfSpaceOnly`] (`--method auto`), optically small.
/// * The shape correction follows [`crate::integrator::Correction::applies`]: by default a
///   material's own `shape_correction`, else the small objects.
pub fn plan(scene: &Scene, method: Method) -> Vec<Option<ObjectPlan>> {
    (0..scene.objects().len() as u32)
        .map(|i| {
            let t = scene.objects()[i as usize].material.translucent()?;
            let small = is_optically_small(scene, i);
            let clear = is_clear(t);
            Some(match method {
                Method::PathTraced => ObjectPlan {
                    path_traced: true,
                    corrected: false,
                    small,
                    clear,
                },
                Method::Bssrdf { policy, .. } => {
                    let path_traced = (clear
                        || (policy.coverage == Coverage::HalfSpaceOnly && small))
                        && scene.can_path_trace(i);
                    ObjectPlan {
                        path_traced,
                        corrected: !path_traced
                            && !clear
                            && policy.correction.applies(t.shape_correction, small),
                        small,
                        clear,
                    }
                }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::field::MediumField;
    use crate::geometry::{TriangleMesh, primitives};
    use crate::integrator::Correction;
    use crate::light::Light;
    use crate::scene::{Material, RenderSettings, SceneBuilder, Translucent};
    use bssrdf_core::Rgb;
    use glam::DVec3;
    use het_estimate::{Coefficients, Estimator};
    use std::f64::consts::TAU;

    /// A closed surface of revolution about z: the profile `(ρ, z)` at `n` points, swept
    /// through `m` angles. A closed `profile` (the torus's circle) wraps around; an open one
    /// (from the axis to the axis: a capped cylinder) is closed by the poles it starts and
    /// ends on, which are welded into one vertex each.
    fn revolve(profile: &[(f64, f64)], closed_profile: bool, m: u32) -> TriangleMesh {
        let n = profile.len() as u32;
        let mut positions = Vec::new();
        let mut index = Vec::new();
        for &(rho, z) in profile {
            let on_axis = rho == 0.0;
            let first = positions.len() as u32;
            for j in 0..m {
                let a = TAU * f64::from(j) / f64::from(m);
                if !on_axis || j == 0 {
                    positions.push(DVec3::new(rho * a.cos(), rho * a.sin(), z));
                }
            }
            index.push((first, on_axis));
        }
        let vertex = |i: u32, j: u32| {
            let (first, on_axis) = index[(i % n) as usize];
            if on_axis { first } else { first + j % m }
        };
        let rows = if closed_profile { n } else { n - 1 };
        let mut triangles = Vec::new();
        for i in 0..rows {
            for j in 0..m {
                let (a, b) = (vertex(i, j), vertex(i, j + 1));
                let (c, d) = (vertex(i + 1, j), vertex(i + 1, j + 1));
                for t in [[a, c, d], [a, d, b]] {
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        triangles.push(t);
                    }
                }
            }
        }
        let mut mesh = TriangleMesh::new(positions, triangles);
        mesh.orient_outward();
        mesh
    }

    fn torus(major: f64, minor: f64) -> TriangleMesh {
        let profile: Vec<_> = (0..24)
            .map(|k| {
                let a = TAU * f64::from(k) / 24.0;
                (major + minor * a.cos(), minor * a.sin())
            })
            .collect();
        revolve(&profile, true, 48)
    }

    fn cylinder(radius: f64, height: f64) -> TriangleMesh {
        let h = 0.5 * height;
        revolve(&[(0.0, -h), (radius, -h), (radius, h), (0.0, h)], false, 48)
    }

    /// `mesh` of a medium with σa 0.01, σs 0.99 (ϖ 0.99, σt 1: sizes in mean free paths; the
    /// diffusion length 1/σtr = 1/√(3·0.01·1) = 5.8 mfp) under a uniform sky.
    fn scene_of(mesh: TriangleMesh) -> Scene {
        let camera = Camera::orthographic(
            DVec3::new(0.0, 0.0, 50.0),
            DVec3::NEG_Z,
            DVec3::Y,
            40.0,
            40.0,
            8,
            8,
        )
        .unwrap();
        let medium = MediumField::homogeneous(Coefficients::grey(0.01, 0.99)).unwrap();
        SceneBuilder::new(RenderSettings::new(8, 8, 1), camera)
            .light(Light::environment(Rgb::ONE).unwrap())
            .object(
                "body",
                mesh,
                Material::Translucent(Translucent::new("m", medium, 0.0, 1.3)),
            )
            .build()
            .unwrap()
    }

    /// Bodies a few mean free paths across (a torus, a thin disk, a cylinder and a cube:
    /// all thinner than 5 diffusion lengths, 29 mfp): `auto` path-traces each and `sone`
    /// renders each with its BSSRDF, corrected under `--shape-correction auto`; a sphere 200
    /// mfp across gets the BSSRDF, uncorrected, under both.
    #[test]
    fn auto_path_traces_small_bodies_and_keeps_the_bssrdf_on_large_ones() {
        let small = [
            ("torus", torus(6.0, 2.0)),
            ("disk", cylinder(8.0, 1.0)),
            ("cylinder", cylinder(2.0, 10.0)),
            (
                "cube",
                primitives::cuboid(DVec3::splat(-2.0), DVec3::splat(2.0)),
            ),
        ];
        let auto = Method::auto(Estimator::Sone(Default::default()));
        let sone = Method::bssrdf(Estimator::Sone(Default::default()), None)
            .with_correction(Correction::Auto);
        for (name, mesh) in small {
            let scene = scene_of(mesh);
            assert!(scene.can_path_trace(0), "{name}: closed, homogeneous");
            let p = plan(&scene, auto)[0].unwrap();
            assert!(
                p.small && p.path_traced && !p.corrected,
                "{name} under auto: {p:?}"
            );
            let p = plan(&scene, sone)[0].unwrap();
            assert!(
                p.small && !p.path_traced && p.corrected,
                "{name} under sone: {p:?}"
            );
            let p = plan(&scene, Method::PathTraced)[0].unwrap();
            assert!(p.path_traced && !p.corrected, "{name} under pt: {p:?}");
        }
        let large = scene_of(primitives::icosphere(DVec3::ZERO, 100.0, 3));
        for method in [auto, sone] {
            let p = plan(&large, method)[0].unwrap();
            assert!(
                !p.small && !p.path_traced && !p.corrected,
                "large sphere: {p:?}"
            );
        }
    }
}
