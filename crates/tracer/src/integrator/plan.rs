//! How a method renders each translucent object: its BSSRDF or the path tracer, and with or
//! without the shape correction. One decision, read by the integrator that prepares the
//! render, by the warnings and by the sidecar.

use crate::integrator::warnings::is_optically_small;
use crate::integrator::{Coverage, Method};
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
