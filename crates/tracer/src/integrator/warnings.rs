//! Things about a scene that make a render misleading: nothing to render, lights the path
//! tracer cannot reach through a refractive boundary, opaque objects inside a translucent
//! one that the BSSRDF methods do not see, and translucent objects too small for a half-space
//! profile; and what the loader read but could not honour ([`Scene::load_notes`]). Printed by
//! the CLI and recorded in the sidecar.

use crate::integrator::Method;
use crate::light::Light;
use crate::scene::Scene;

/// The warnings for rendering `scene` with `method`.
pub fn scene_warnings(scene: &Scene, method: Method) -> Vec<String> {
    let mut warnings = scene.load_notes().to_vec();
    if !scene.objects().iter().any(|o| o.emitter.is_none()) {
        warnings.push("the scene has no shapes: only lights seen directly can appear".to_string());
    }
    if scene.lights().is_empty() {
        warnings.push("the scene has no lights: the image is black".to_string());
    } else if scene.lights().iter().all(|l| matches!(l, Light::Beam(_))) {
        warnings.push(
            "the scene's only lights are beams, which `render` does not trace (they light the \
             beam experiment): the image is black; add a directional, point, quad or \
             environment light"
                .to_string(),
        );
    }
    match method {
        Method::PathTraced => warnings.extend(unreachable_lights(scene)),
        Method::Bssrdf { .. } => {
            warnings.extend(hidden_cores(scene));
            warnings.extend(small_objects(scene));
        }
    }
    warnings
}

/// One warning per delta light (directional, point) that cannot light the inside of a
/// refractive (η > 1) translucent object in a path tracer, with that light's share of the
/// power of every light `render` samples ([`Light::power`]).
fn unreachable_lights(scene: &Scene) -> Vec<String> {
    let refractive: Vec<String> = scene
        .translucent_objects()
        .filter(|(_, t)| t.eta != 1.0)
        .map(|(i, t)| format!("`{}` (eta = {})", scene.objects()[i as usize].name, t.eta))
        .collect();
    if refractive.is_empty() {
        return Vec::new();
    }
    let (lo, hi) = scene.geometry().bounds();
    let radius = if lo.x <= hi.x {
        0.5 * (hi - lo).length()
    } else {
        1.0
    };
    let sampled = || {
        scene
            .lights()
            .iter()
            .filter(|l| !matches!(l, Light::Beam(_)))
    };
    let total: f64 = sampled().map(|l| l.power(radius)).sum();
    let mut warnings = Vec::new();
    for (j, light) in scene.lights().iter().enumerate() {
        if matches!(light, Light::Beam(_)) || !light.is_delta() {
            continue;
        }
        let share = if total > 0.0 {
            100.0 * light.power(radius) / total
        } else {
            0.0
        };
        let kind = match light {
            Light::Directional(_) => "directional",
            _ => "point",
        };
        warnings.push(format!(
            "light[{j}] ({kind} light, {share:.3} % of the scene's light by power) cannot light \
             the inside of {}: a path tracer cannot connect to a delta light through a \
             refractive boundary, so its light scattered inside is lost; use a quad or \
             environment light",
            refractive.join(", ")
        ));
    }
    warnings
}

/// One warning per opaque object inside or crossing a translucent one: the BSSRDF methods
/// treat the translucent object as homogeneous material throughout.
fn hidden_cores(scene: &Scene) -> Vec<String> {
    scene
        .opaque_inside_media()
        .into_iter()
        .map(|(t, o)| {
            format!(
                "object `{}` lies inside or crosses the translucent object `{}`: BSSRDF methods \
                 model `{}` as filled with its medium and do not see `{}` inside it (only where \
                 it blocks light outside); render with `--method pt` to include it",
                scene.objects()[o as usize].name,
                scene.objects()[t as usize].name,
                scene.objects()[t as usize].name,
                scene.objects()[o as usize].name
            )
        })
        .collect()
}

/// Objects whose thinnest side spans fewer diffusion lengths than this are reported by
/// [`scene_warnings`].
pub const SMALL_OBJECT_DIFFUSION_LENGTHS: f64 = 5.0;

/// One warning per translucent object whose bounding box's thinnest side is shorter than
/// [`SMALL_OBJECT_DIFFUSION_LENGTHS`] diffusion lengths 1/σtr of its most translucent part
/// (σtr = √(3σa(σa + (1 − g)σs)) at the field's smallest σa, any channel). Every BSSRDF profile
/// here is a half-space profile: on such an object light that leaves through other faces, or
/// that a small curved body never returns, is not modelled (measured on the bunny: 16 % darker
/// than the path tracer with the exact profile; docs/physics.md#hazards).
fn small_objects(scene: &Scene) -> Vec<String> {
    let mut warnings = Vec::new();
    for (i, t) in scene.translucent_objects() {
        let (lo, hi) = scene.geometry().object_bounds(i);
        let thinnest = (hi - lo).min_element();
        let b = t.medium.field_bounds();
        let longest = (0..3)
            .filter_map(|c| {
                let (a, s) = (b.min.sigma_a[c], b.max.sigma_s[c] * (1.0 - t.g));
                let sigma_tr = (3.0 * a * (a + s)).sqrt();
                (sigma_tr > 0.0).then_some(1.0 / sigma_tr)
            })
            .fold(0.0, f64::max);
        let longest = if longest > 0.0 {
            longest
        } else {
            f64::INFINITY
        };
        if thinnest.is_finite() && thinnest < SMALL_OBJECT_DIFFUSION_LENGTHS * longest {
            warnings.push(format!(
                "translucent object `{}` is {thinnest:.3} across its thinnest side, {:.2} \
                 diffusion lengths of its most translucent part (1/σtr = {}): BSSRDF profiles \
                 assume a half-space, so light leaving through other faces, or never returning \
                 from a small curved part, is not modelled; compare with `--method pt`",
                scene.objects()[i as usize].name,
                thinnest / longest,
                if longest.is_finite() {
                    format!("{longest:.3}")
                } else {
                    "∞".to_string()
                }
            ));
        }
    }
    warnings
}
