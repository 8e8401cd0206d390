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
}

/// The plan of every object of `scene` under `method`, by object index (`None` for objects
/// that are not translucent).
///
/// * `pt` path-traces every translucent object.
/// * A BSSRDF method renders each with its BSSRDF, except, under [`Coverage::HalfSpaceOnly`]
///   (`--method auto`), the optically small objects the path tracer can walk (a closed mesh,
///   a medium defined in space or read through texture coordinates the mesh has).
/// * The shape correction follows [`crate::integrator::Correction::applies`]: by default a
///   material's own `shape_correction`, else the small objects.
pub fn plan(scene: &Scene, method: Method) -> Vec<Option<ObjectPlan>> {
    (0..scene.objects().len() as u32)
        .map(|i| {
            let t = scene.objects()[i as usize].material.translucent()?;
            let small = is_optically_small(scene, i);
            Some(match method {
                Method::PathTraced => ObjectPlan {
                    path_traced: true,
                    corrected: false,
                    small,
                },
                Method::Bssrdf { policy, .. } => {
                    let path_traced = policy.coverage == Coverage::HalfSpaceOnly
                        && small
                        && scene.can_path_trace(i);
                    ObjectPlan {
                        path_traced,
                        corrected: !path_traced
                            && policy.correction.applies(t.shape_correction, small),
                        small,
                    }
                }
            })
        })
        .collect()
}
