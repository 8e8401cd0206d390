//! Things about a scene that make a render misleading: nothing to render, lights the path
//! tracer cannot reach through a refractive boundary, opaque objects inside a translucent
//! one that the BSSRDF methods do not see, translucent objects too small for a half-space
//! profile, and media that change with depth below the surface the camera sees; and what the
//! loader read but could not honour ([`Scene::load_notes`]). Printed by the CLI and recorded in
//! the sidecar.

use crate::field::Variation;
use crate::geometry::Hit;
use crate::integrator::Method;
use crate::integrator::plan::{ObjectPlan, plan};
use crate::light::Light;
use crate::optical_size::light_reach;
use crate::scene::Scene;

/// A warning about a render: one line for the terminal, and the whole explanation for the
/// sidecar and `render --verbose`. Each kind of warning is one [`Warning`] naming every object
/// it concerns, so that no explanation repeats per object.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// One line: the objects concerned, what is wrong and what to do.
    pub summary: String,
    /// The full text: the summary's facts, why they matter and what was measured.
    pub detail: String,
}

impl Warning {
    /// A warning whose one line says everything.
    fn line(text: impl Into<String>) -> Self {
        let text = text.into();
        Self {
            summary: text.clone(),
            detail: text,
        }
    }

    /// Whether the summary or the full text contains `needle` (for tests and callers that
    /// look for one kind of warning).
    pub fn contains(&self, needle: &str) -> bool {
        self.summary.contains(needle) || self.detail.contains(needle)
    }
}

impl std::fmt::Display for Warning {
    /// The full text.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.detail)
    }
}

/// `items` as English: "`a`", "`a` and `b`", "`a`, `b` and `c`".
fn listed(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The warnings for rendering `scene` with `method`.
pub fn scene_warnings(scene: &Scene, method: Method) -> Vec<Warning> {
    let mut warnings = load_notes(scene);
    if !scene.objects().iter().any(|o| o.emitter.is_none()) {
        warnings.push(Warning::line(
            "the scene has no shapes: only lights seen directly can appear",
        ));
    }
    if scene.lights().is_empty() {
        warnings.push(Warning::line(
            "the scene has no lights: the image is black; add a `[[light]]`",
        ));
    } else if scene.lights().iter().all(|l| matches!(l, Light::Beam(_))) {
        warnings.push(Warning {
            summary: "the scene's only lights are beams, which `render` does not trace: add a \
                      directional, point, quad or environment light"
                .to_string(),
            detail: "the scene's only lights are beams, which `render` does not trace (they \
                     light the beam experiment): the image is black; add a directional, point, \
                     quad or environment light"
                .to_string(),
        });
    }
    let plans = plan(scene, method);
    let traced = |i: u32| plans[i as usize].is_some_and(|p| p.path_traced);
    let bssrdf = |i: u32| plans[i as usize].is_some_and(|p| !p.path_traced);
    warnings.extend(unreachable_lights(scene, &traced));
    warnings.extend(hidden_cores(scene, &bssrdf));
    warnings.extend(clear_media(scene, &plans));
    warnings.extend(small_objects(scene, &plans));
    warnings.extend(depth_varying(scene, &bssrdf));
    warnings
}

/// One warning per file of what the loader read but could not honour
/// ([`Scene::load_notes`]): the line names the file, the materials and what is not rendered.
fn load_notes(scene: &Scene) -> Vec<Warning> {
    let mut files: Vec<&str> = Vec::new();
    for n in scene.load_notes() {
        if !files.contains(&n.file.as_str()) {
            files.push(&n.file);
        }
    }
    files
        .into_iter()
        .map(|file| {
            let notes: Vec<_> = scene
                .load_notes()
                .iter()
                .filter(|n| n.file == file)
                .collect();
            let name = std::path::Path::new(file)
                .file_name()
                .map_or(file.to_string(), |n| n.to_string_lossy().into_owned());
            let summary = match notes.as_slice() {
                [one] => format!("`{name}`, {}: {}", one.subject, first_clause(&one.text)),
                _ => {
                    let mut subjects: Vec<String> = Vec::new();
                    for n in &notes {
                        if !subjects.contains(&n.subject) {
                            subjects.push(n.subject.clone());
                        }
                    }
                    format!(
                        "`{name}`: {} things in {} are not rendered as written (the sidecar or \
                         `--verbose` lists them)",
                        notes.len(),
                        listed(&subjects)
                    )
                }
            };
            let detail = notes
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join("; ");
            Warning { summary, detail }
        })
        .collect()
}

/// A note's text up to its first parenthesis or colon after the first few words: the fact
/// without its explanation.
fn first_clause(text: &str) -> &str {
    let cut = text
        .char_indices()
        .find(|&(i, c)| i > 8 && (c == '(' || c == ':'))
        .map_or(text.len(), |(i, _)| i);
    text[..cut].trim_end()
}

/// One warning for the delta lights (directional, point) that cannot light the inside of a
/// refractive (η > 1) translucent object in a path tracer (those for which `traced` holds),
/// with each light's share of the power of every light `render` samples ([`Light::power`]).
fn unreachable_lights(scene: &Scene, traced: &dyn Fn(u32) -> bool) -> Vec<Warning> {
    let refractive: Vec<String> = scene
        .translucent_objects()
        .filter(|(i, t)| t.eta != 1.0 && traced(*i))
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
    let mut lights = Vec::new();
    for (j, light) in scene.lights().iter().enumerate() {
        if matches!(light, Light::Beam(_)) || !light.is_delta() {
            continue;
        }
        let share = if total > 0.0 {
            100.0 * light.power(radius) / total
        } else {
            0.0
        };
        let kind = light.kind();
        lights.push(format!(
            "light[{j}] ({kind} light, {share:.3} % of the scene's light by power)"
        ));
    }
    if lights.is_empty() {
        return Vec::new();
    }
    let (lights, objects) = (listed(&lights), listed(&refractive));
    vec![Warning {
        summary: format!(
            "{lights} cannot light the inside of {objects} in the path tracer: use a quad or \
             environment light"
        ),
        detail: format!(
            "{lights} cannot light the inside of {objects}: a path tracer cannot connect to a \
             delta light through a refractive boundary, so its light scattered inside is lost; \
             use a quad or environment light"
        ),
    }]
}

/// One warning for the opaque objects inside or crossing a translucent one rendered by a
/// BSSRDF (`bssrdf` holds for it): the BSSRDF methods treat the translucent object as
/// homogeneous material throughout. An opaque object that only rests against the translucent
/// one ([`merely_touching`]: a statue on a floor) is not reported.
fn hidden_cores(scene: &Scene, bssrdf: &dyn Fn(u32) -> bool) -> Vec<Warning> {
    let name = |i: u32| format!("`{}`", scene.objects()[i as usize].name);
    let pairs: Vec<(u32, u32)> = scene
        .opaque_inside_media()
        .into_iter()
        .filter(|&(t, o)| bssrdf(t) && !merely_touching(scene, t, o))
        .collect();
    if pairs.is_empty() {
        return Vec::new();
    }
    let described: Vec<String> = pairs
        .iter()
        .map(|&(t, o)| format!("{} inside or across {}", name(o), name(t)))
        .collect();
    let media: Vec<String> = pairs.iter().map(|&(t, _)| name(t)).collect();
    let mut media_unique: Vec<String> = Vec::new();
    for m in media {
        if !media_unique.contains(&m) {
            media_unique.push(m);
        }
    }
    let described = listed(&described);
    vec![Warning {
        summary: format!(
            "{described}: the BSSRDF methods do not see it; render with `--method pt` to include \
             it"
        ),
        detail: format!(
            "{described}: BSSRDF methods model {} as filled with its medium and do not see the \
             opaque object inside it (only where it blocks light outside); render with \
             `--method pt` to include it",
            listed(&media_unique)
        ),
    }]
}

/// Relative depth (of the translucent object's thinnest side) below which an opaque object
/// that reaches into a translucent one only from outside counts as resting against it.
const CONTACT_DEPTH: f64 = 0.01;

/// Whether opaque object `o` only rests against translucent object `t` (a statue on a floor, a
/// mesh sunk into a plinth by rounding): along some axis their extents overlap by less than
/// [`CONTACT_DEPTH`] of `t`'s thinnest side, and neither extent holds the other there (so
/// that a thin core inside `t` still counts). What the BSSRDF misses in such a sliver is
/// negligible; the exact volume test of [`Scene::opaque_inside_media`] counts it.
fn merely_touching(scene: &Scene, t: u32, o: u32) -> bool {
    let (tlo, thi) = scene.geometry().object_bounds(t);
    let (olo, ohi) = scene.geometry().object_bounds(o);
    let tolerance = CONTACT_DEPTH * (thi - tlo).min_element();
    (0..3).any(|k| {
        let overlap = thi[k].min(ohi[k]) - tlo[k].max(olo[k]);
        let nested =
            (tlo[k] <= olo[k] && ohi[k] <= thi[k]) || (olo[k] <= tlo[k] && thi[k] <= ohi[k]);
        overlap <= tolerance && !nested
    })
}

/// One warning for the clear translucent objects (their medium does not scatter) that a
/// BSSRDF renders because the path tracer cannot walk them (an open mesh, or a UV-mapped
/// medium without texture coordinates): every BSSRDF profile is zero in them.
fn clear_media(scene: &Scene, plans: &[Option<ObjectPlan>]) -> Vec<Warning> {
    let objects: Vec<String> = scene
        .translucent_objects()
        .filter(|(i, _)| plans[*i as usize].is_some_and(|p| p.clear && !p.path_traced))
        .map(|(i, _)| format!("`{}`", scene.objects()[i as usize].name))
        .collect();
    if objects.is_empty() {
        return Vec::new();
    }
    let objects = listed(&objects);
    vec![Warning {
        summary: format!(
            "{objects}: the medium does not scatter, so a BSSRDF renders it black; close the \
             mesh so that it is path traced"
        ),
        detail: format!(
            "{objects}: the medium does not scatter (σs = 0: a clear absorbing dielectric), so \
             every BSSRDF profile is zero in it and a BSSRDF method renders no light through \
             it; such objects are path traced under every method when the path tracer can walk \
             them, which needs a closed mesh (and a medium defined in space, or texture \
             coordinates for a UV-mapped one)"
        ),
    }]
}

/// Camera samples per side of the grid that measures an object's share of the image.
const SHARE_GRID: u32 = 128;

/// One warning per translucent object whose bounding box's thinnest side is shorter than
/// [`SMALL_OBJECT_DIFFUSION_LENGTHS`](crate::optical_size::SMALL_OBJECT_DIFFUSION_LENGTHS) times the longer of the diffusion length 1/σtr and the
/// transport mean free path 1/σt' of its most translucent part (σt' = σa + (1 − g)σs, σtr =
/// √(3σa σt'), at the field's smallest σa and σt', any channel), with the share of the image's
/// pixels that see the object. Every BSSRDF profile here is a half-space profile: on such an
/// object light that leaves through other faces, or that a small curved body never returns,
/// is not modelled. Measured against the path tracer (docs/shapes.md, `examples/shapes.rs`):
/// slabs of 0.5 and 2 mfp render ×2.2 to ×6.7 and ×0.85 to ×1.47 too bright, a sphere of
/// radius 1 mfp ×0.40 to ×0.95; at g = 0.8 sizes in transport mean free paths are 5× smaller
/// and the errors grow (docs/physics.md#hazards).
fn small_objects(scene: &Scene, plans: &[Option<ObjectPlan>]) -> Vec<Warning> {
    // (corrected, one-line fact, full fact) per object.
    let mut found: Vec<(bool, String, String)> = Vec::new();
    for (i, t) in scene.translucent_objects() {
        let Some(plan) = plans[i as usize].filter(|p| p.small && !p.path_traced) else {
            continue;
        };
        let name = &scene.objects()[i as usize].name;
        let (lo, hi) = scene.geometry().object_bounds(i);
        let extent = hi - lo;
        let thinnest = extent.min_element();
        let b = t.medium.field_bounds();
        let (longest, diffusive) = light_reach(b.min, t.g);
        let share = 100.0 * image_share(scene, i);
        let (unit, symbol) = if diffusive {
            ("diffusion lengths", "1/σtr")
        } else {
            ("transport mean free paths", "1/σt'")
        };
        let value = if longest.is_finite() {
            format!("{longest:.3}")
        } else {
            "∞".to_string()
        };
        // A thin part (a slab: its thinnest side well below the others) loses light through
        // the far face, which a half-space keeps: too bright; a small compact body returns
        // less light than a half-space: too dark (docs/shapes.md).
        let middle = extent.x + extent.y + extent.z - extent.max_element() - thinnest;
        let sign = if thinnest < 0.5 * middle {
            "a thin part: a half-space profile renders it too bright (×0.85 to ×6.7 for slabs of 0.5 to 2 mfp)"
        } else {
            "a small body: a half-space profile renders it too dark (×0.40 to ×0.95 for a sphere of radius 1 mfp)"
        };
        let ratio = thinnest / longest;
        found.push((
            plan.corrected,
            format!("`{name}` ({ratio:.2} {unit} across)"),
            format!(
                "translucent object `{name}` ({share:.1} % of the image's pixels) is \
                 {thinnest:.3} across its thinnest side, {ratio:.2} {unit} of its most \
                 translucent part ({symbol} = {value}, g = {}): {sign}",
                t.g
            ),
        ));
    }
    let mut warnings = Vec::new();
    for corrected in [false, true] {
        let (short, full): (Vec<String>, Vec<String>) = found
            .iter()
            .filter(|f| f.0 == corrected)
            .map(|f| (f.1.clone(), f.2.clone()))
            .unzip();
        if short.is_empty() {
            continue;
        }
        let (is, it) = if short.len() == 1 {
            ("is", "it")
        } else {
            ("are", "them")
        };
        let summary = if corrected {
            format!(
                "{} {is} too small for a half-space profile; the shape correction scales the \
                 BSSRDF (approximate): `--method auto` path-traces {it}",
                listed(&short)
            )
        } else {
            format!(
                "{} {is} too small for a half-space profile: `--method auto` path-traces {it}, \
                 `--shape-correction on` corrects the BSSRDF",
                listed(&short)
            )
        };
        let consequence = if corrected {
            "the shape correction scales the BSSRDF so that it answers uniform light as the \
             volume does (measured by random walks in it: within 15 % of the path tracer under \
             uniform light, docs/shapes.md); under other light it is a first-order correction"
        } else {
            "the shape correction is off (`render --shape-correction auto` or `on`, or the \
             material's `shape_correction = true`, turns it on)"
        };
        warnings.push(Warning {
            summary,
            detail: format!(
                "{}; {consequence}; `--method auto` path-traces such objects",
                full.join("; ")
            ),
        });
    }
    warnings
}

/// The share of an object's pixels beyond which [`depth_varying`] warns.
const DEPTH_WARNING_SHARE: f64 = 0.05;
/// A surface is oblique to a field when its normal is more than 25° from the directions the
/// field is constant along ([`Variation::depth_sine`] above sin 25°).
const OBLIQUE_SINE: f64 = 0.422_618_261_740_699_4;

/// One warning per translucent object whose medium changes with depth below more than
/// [`DEPTH_WARNING_SHARE`] of the object's pixels. Every estimator reads the coefficients on
/// the surface and takes them to continue unchanged below it (the kernel's derivation states
/// it, docs/kernel.md#assumptions); a field defined in space (a pattern or a planar image) is
/// constant only along its projection axis (a stripe also along its bands), so below a
/// surface oblique to those directions the medium the light crosses is not the one its
/// surface shows. Measured with the kernel (docs/shapes.md, "What remains"): 0.81 of the path
/// tracer over the heterogeneous bunny (`examples/scenes/bunny.toml`), 0.95 with the shape
/// correction, whose walks go through the medium (0.89 when they went through the coefficients
/// at the surface); 1.03–1.06 with a layer boundary 0.05–0.5 below a flat surface.
fn depth_varying(scene: &Scene, bssrdf: &dyn Fn(u32) -> bool) -> Vec<Warning> {
    let mut tallies: Vec<DepthTally<'_>> = scene
        .translucent_objects()
        .filter(|(i, _)| bssrdf(*i))
        .map(|(object, t)| DepthTally {
            object,
            fields: t
                .medium
                .named_fields()
                .into_iter()
                .filter_map(|(name, f)| f.variation().map(|v| (name, v)))
                .collect(),
            seen: 0,
            oblique: 0,
        })
        .filter(|t| !t.fields.is_empty())
        .collect();
    if tallies.is_empty() {
        return Vec::new();
    }
    // One sweep of the pixel grid for every object at once.
    for_pixel_hits(scene, |hit| {
        if let Some(t) = tallies.iter_mut().find(|t| t.object == hit.object) {
            t.seen += 1;
            if t.fields
                .iter()
                .any(|(_, v)| v.depth_sine(hit.ns) > OBLIQUE_SINE)
            {
                t.oblique += 1;
            }
        }
    });
    let mut short = Vec::new();
    let mut full = Vec::new();
    for DepthTally {
        object: i,
        fields,
        seen,
        oblique,
    } in tallies
    {
        let share = if seen > 0 {
            f64::from(oblique) / f64::from(seen)
        } else {
            0.0
        };
        if share <= DEPTH_WARNING_SHARE {
            continue;
        }
        let name = &scene.objects()[i as usize].name;
        let described = fields
            .iter()
            .map(|(name, v)| format!("`{name}` {}", v.describe()))
            .collect::<Vec<_>>()
            .join(", ");
        short.push(format!("`{name}` ({:.0} % of its pixels)", 100.0 * share));
        full.push(format!(
            "translucent object `{name}`: its medium ({described}) changes with depth below \
             {:.1} % of its pixels",
            100.0 * share
        ));
    }
    if short.is_empty() {
        return Vec::new();
    }
    let its = if short.len() == 1 { "its" } else { "their" };
    vec![Warning {
        summary: format!(
            "the medium of {} changes with depth below the surface, which the BSSRDF estimators \
             do not see: compare with `--method pt`",
            listed(&short)
        ),
        detail: format!(
            "{} (surfaces tilted more than 25° from the directions the medium is constant \
             along); every BSSRDF estimator reads the coefficients on the surface and takes \
             them to continue unchanged below it, which measured from 0.81 (the heterogeneous \
             bunny; 0.95 with the material's `shape_correction`, whose walks go through the \
             medium) to 1.06 (a layer below a flat surface) of the path tracer with `kernel` \
             (docs/shapes.md); compare {its} render with `--method pt`",
            full.join("; ")
        ),
    }]
}

/// One object's fields that vary in space, and how many of its grid pixels [`depth_varying`]
/// saw, and saw over oblique surfaces.
struct DepthTally<'a> {
    object: u32,
    fields: Vec<(&'a str, Variation)>,
    seen: u32,
    oblique: u32,
}

/// Calls `f` with the first hit of every camera ray on a grid of at most [`SHARE_GRID`]²
/// pixel centres spread evenly over the image; returns the number of grid pixels.
fn for_pixel_hits(scene: &Scene, mut f: impl FnMut(&Hit)) -> u32 {
    let camera = scene.camera();
    let (w, h) = camera.resolution();
    let (nx, ny) = (w.min(SHARE_GRID), h.min(SHARE_GRID));
    for j in 0..ny {
        for i in 0..nx {
            let px = ((i as f64 + 0.5) * w as f64 / nx as f64).floor() + 0.5;
            let py = ((j as f64 + 0.5) * h as f64 / ny as f64).floor() + 0.5;
            if let Some(hit) = scene.geometry().intersect(&camera.ray(px, py)) {
                f(&hit);
            }
        }
    }
    nx * ny
}

/// The fraction of the image's pixels whose camera ray first hits `object`, from a grid of at
/// most [`SHARE_GRID`]² pixel centres spread evenly over the image.
fn image_share(scene: &Scene, object: u32) -> f64 {
    let mut seen = 0u32;
    let total = for_pixel_hits(scene, |hit| seen += u32::from(hit.object == object));
    f64::from(seen) / f64::from(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::field::{Axis, Field, MediumField, PlanarProjection, Variation};
    use crate::geometry::{TriangleMesh, primitives};
    use crate::scene::{Material, RenderSettings, SceneBuilder, Translucent};
    use bssrdf_core::Rgb;
    use glam::DVec3;
    use het_estimate::Coefficients;

    /// One translucent object `name` (η 1, anisotropy `g`) under a uniform sky, seen along −z
    /// by a 64 × 64 orthographic view 4.4 wide.
    fn viewed_scene(name: &str, mesh: TriangleMesh, medium: MediumField, g: f64) -> Scene {
        let camera = Camera::orthographic(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::NEG_Z,
            DVec3::Y,
            4.4,
            4.4,
            64,
            64,
        )
        .unwrap();
        SceneBuilder::new(RenderSettings::new(64, 64, 1), camera)
            .light(Light::environment(Rgb::ONE).unwrap())
            .object(
                name,
                mesh,
                Material::Translucent(Translucent::new("m", medium, g, 1.0)),
            )
            .build()
            .unwrap()
    }

    /// A sphere of radius 1.5 (σa = σs = 1) seen whole by [`viewed_scene`]'s view: it covers
    /// π·1.5²/4.4² = 36.5 % of the image.
    fn sphere_scene(g: f64) -> Scene {
        let medium = MediumField::homogeneous(Coefficients::grey(1.0, 1.0)).unwrap();
        viewed_scene(
            "ball",
            primitives::icosphere(DVec3::ZERO, 1.5, 3),
            medium,
            g,
        )
    }

    /// A check (σa 0.01 and 0.1, cells of 0.5) projected along `axis`.
    fn check_along(axis: Axis) -> Field {
        let projection = PlanarProjection::new(axis, DVec3::ZERO);
        Field::check(0.5, [Rgb::splat(0.01), Rgb::splat(0.1)], projection).unwrap()
    }

    /// `mesh` in [`viewed_scene`], its σa `sigma_a` (σs 1, g 0).
    fn textured_scene(mesh: TriangleMesh, sigma_a: Field) -> Scene {
        let medium = MediumField::new(sigma_a, Field::constant(Rgb::ONE).unwrap());
        viewed_scene("body", mesh, medium, 0.0)
    }

    /// The share of the depth warning, or `None` without one.
    fn depth_share(scene: &Scene) -> Option<f64> {
        let warnings = scene_warnings(scene, "kernel".parse().unwrap());
        let w = warnings.iter().find(|w| w.contains("changes with depth"))?;
        w.detail
            .split("below ")
            .nth(1)
            .and_then(|s| s.split(" %").next())
            .and_then(|s| s.parse().ok())
    }

    /// A box seen from above with its check along z (the view axis) shows the medium below its
    /// top face: no warning (nor with a stripe varying along x). The same box with the check
    /// along x: every pixel's medium changes with depth. A sphere of radius R seen along z with the check along z: the normal at
    /// distance ρ from the axis has n_z = √(1 − ρ²/R²), below cos 25° where ρ/R > sin 25°,
    /// which is 1 − sin² 25° = cos² 25° = 82.1 % of the projected disk. A constant medium and
    /// the path tracer get no warning.
    #[test]
    fn depth_warning_names_the_share_of_oblique_pixels() {
        let block = || primitives::cuboid(DVec3::new(-1.0, -1.0, -2.0), DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(
            depth_share(&textured_scene(block(), check_along(Axis::Z))),
            None
        );
        let along_x =
            depth_share(&textured_scene(block(), check_along(Axis::X))).expect("a warning");
        assert!((along_x - 100.0).abs() < 1e-9, "{along_x} %");
        let ball = depth_share(&textured_scene(
            primitives::icosphere(DVec3::ZERO, 1.5, 4),
            check_along(Axis::Z),
        ))
        .expect("a warning");
        let want = 100.0 * (25f64.to_radians().cos()).powi(2);
        // The rim's pixel row is 3 % of the disk's pixels; facets move the normals a little.
        assert!((ball - want).abs() < 3.0, "{ball} %, want {want} %");
        assert_eq!(depth_share(&sphere_scene(0.0)), None);
        // A stripe along z varying along x only, on the box seen from above: the top face's
        // normal is across x, so nothing changes with depth there.
        let projection = PlanarProjection::new(Axis::Z, DVec3::ZERO);
        let stripe =
            Field::stripe(0.5, 0.0, [Rgb::splat(0.01), Rgb::splat(0.1)], projection).unwrap();
        assert_eq!(stripe.variation(), Some(Variation::Along(DVec3::X)));
        let v = stripe.variation().unwrap();
        assert_eq!(v.depth_sine(DVec3::Z), 0.0);
        assert_eq!(v.depth_sine(DVec3::Y), 0.0);
        assert_eq!(v.depth_sine(DVec3::NEG_X), 1.0);
        assert_eq!(depth_share(&textured_scene(block(), stripe.clone())), None);
        // The sphere with that stripe: oblique where |n_x| > sin 25°, outside the band
        // |x| < R sin 25° of the projected disk, 1 − 2(s√(1 − s²) + asin s)/π = 47.8 % of it
        // (s = sin 25°).
        let ball = depth_share(&textured_scene(
            primitives::icosphere(DVec3::ZERO, 1.5, 4),
            stripe,
        ))
        .expect("a warning");
        let s = 25f64.to_radians().sin();
        let want =
            100.0 * (1.0 - 2.0 * (s * (1.0 - s * s).sqrt() + s.asin()) / std::f64::consts::PI);
        assert!((ball - want).abs() < 3.0, "{ball} %, want {want} %");
        let pt = scene_warnings(
            &textured_scene(block(), check_along(Axis::X)),
            Method::PathTraced,
        );
        assert!(!pt.iter().any(|w| w.contains("changes with depth")));
    }

    /// At g = 0 the ball (3 across) is 6 transport mean free paths (1/σt' = 0.5) and 7.3
    /// diffusion lengths thick: no warning. At g = 0.8 the transport mean free path is
    /// 1/1.2 = 0.833, longer than the diffusion length 1/√3.6 = 0.527, and the ball is 3.6 of
    /// them: the warning says so, with the ball's share of the image.
    #[test]
    fn small_object_warning_covers_forward_scattering_and_gives_the_image_share() {
        let method: Method = "sone".parse().unwrap();
        let small = |w: &Warning| w.contains("half-space");
        assert!(!scene_warnings(&sphere_scene(0.0), method).iter().any(small));
        let warnings = scene_warnings(&sphere_scene(0.8), method);
        let w = warnings
            .iter()
            .find(|w| small(w))
            .expect("a small-object warning");
        assert!(
            w.contains("transport mean free paths") && w.contains("1/σt' = 0.833"),
            "{w}"
        );
        let share: f64 = w
            .detail
            .split("`ball` (")
            .nth(1)
            .and_then(|s| s.split(" %").next())
            .and_then(|s| s.parse().ok())
            .expect("a share");
        let want = 100.0 * std::f64::consts::PI * 1.5 * 1.5 / (4.4 * 4.4);
        // One pixel row of the disk's rim is 2πr/(4.4/64) ≈ 137 pixels of 4096 (3.3 %).
        assert!((share - want).abs() < 2.0, "share {share} %, disk {want} %");
        // The path tracer is not warned.
        assert!(
            !scene_warnings(&sphere_scene(0.8), Method::PathTraced)
                .iter()
                .any(small)
        );
    }

    /// `mesh` (translucent, σa 0.1, σs 1) with an opaque `other` in [`viewed_scene`]'s set-up.
    fn with_opaque(mesh: TriangleMesh, other: TriangleMesh) -> Scene {
        let camera = Camera::orthographic(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::NEG_Z,
            DVec3::Y,
            4.4,
            4.4,
            16,
            16,
        )
        .unwrap();
        let medium = MediumField::homogeneous(Coefficients::grey(0.1, 1.0)).unwrap();
        SceneBuilder::new(RenderSettings::new(16, 16, 1), camera)
            .light(Light::environment(Rgb::ONE).unwrap())
            .object(
                "statue",
                mesh,
                Material::Translucent(Translucent::new("m", medium, 0.0, 1.0)),
            )
            .object("floor", other, Material::diffuse(Rgb::splat(0.5)))
            .build()
            .unwrap()
    }

    /// A block resting on a floor is not "inside or across" it, even sunk into it by 0.5 % of
    /// its size (which the exact volume test counts); sunk by a quarter of its height, or
    /// with the opaque object inside it (a core, however thin), it is.
    #[test]
    fn an_object_resting_on_a_floor_is_not_a_hidden_core() {
        let method: Method = "sone".parse().unwrap();
        let hidden = |scene: &Scene| {
            scene_warnings(scene, method)
                .iter()
                .any(|w| w.contains("inside or across"))
        };
        // A block 2 × 2 × 2 whose bottom is at z = `bottom`.
        let block = |bottom: f64| {
            primitives::cuboid(
                DVec3::new(-1.0, -1.0, bottom),
                DVec3::new(1.0, 1.0, bottom + 2.0),
            )
        };
        let floor = || primitives::cuboid(DVec3::new(-5.0, -5.0, -1.0), DVec3::new(5.0, 5.0, 0.0));
        let sunk = with_opaque(block(-0.01), floor());
        assert_eq!(sunk.opaque_inside_media(), vec![(0, 1)]);
        assert!(!hidden(&sunk));
        assert!(!hidden(&with_opaque(block(0.0), floor())));
        assert!(hidden(&with_opaque(block(-0.5), floor())));
        let core = primitives::cuboid(DVec3::new(-0.5, -0.5, 0.998), DVec3::new(0.5, 0.5, 1.002));
        assert!(hidden(&with_opaque(block(0.0), core)));
    }

    /// A medium that does not scatter is path traced under every BSSRDF method when the path
    /// tracer can walk it (a closed mesh), and the plan and the note say why; a warning names
    /// it only where it cannot be (an open mesh), since a BSSRDF renders it black.
    #[test]
    fn clear_media_are_path_traced_under_every_method() {
        let clear = MediumField::homogeneous(Coefficients {
            sigma_a: Rgb::new(0.1, 0.2, 0.3),
            sigma_s: Rgb::ZERO,
        })
        .unwrap();
        let scene = viewed_scene(
            "glass",
            primitives::icosphere(DVec3::ZERO, 1.5, 3),
            clear.clone(),
            0.0,
        );
        for method in ["sone", "kernel", "jensen-out", "auto"] {
            let m: Method = method.parse().unwrap();
            let p = plan(&scene, m)[0].expect("translucent");
            assert!(p.path_traced && p.clear && !p.corrected, "{method}: {p:?}");
            assert!(scene_warnings(&scene, m).is_empty(), "{method}");
        }
        // A scattering medium keeps its BSSRDF.
        let p = plan(&sphere_scene(0.0), "sone".parse().unwrap())[0].unwrap();
        assert!(!p.path_traced && !p.clear);
        // An open mesh (one triangle) cannot be walked: warned.
        let open = primitives::quad(DVec3::new(-1.0, -1.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0);
        let scene = viewed_scene("sheet", open, clear, 0.0);
        let m: Method = "sone".parse().unwrap();
        assert!(!plan(&scene, m)[0].unwrap().path_traced);
        let w = scene_warnings(&scene, m);
        assert!(
            w.iter()
                .any(|w| w.summary.contains("`sheet`") && w.contains("does not scatter")),
            "{w:?}"
        );
    }

    /// Each kind of warning is one line naming every object it concerns, whatever their
    /// number; the full text gives each object's figures.
    #[test]
    fn one_warning_per_kind_names_every_object() {
        let camera = Camera::orthographic(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::NEG_Z,
            DVec3::Y,
            8.0,
            8.0,
            32,
            32,
        )
        .unwrap();
        let medium = MediumField::homogeneous(Coefficients::grey(1.0, 1.0)).unwrap();
        let mut b = SceneBuilder::new(RenderSettings::new(32, 32, 1), camera)
            .light(Light::environment(Rgb::ONE).unwrap());
        for (k, x) in [-2.5, 0.0, 2.5].into_iter().enumerate() {
            b = b.object(
                format!("ball{k}"),
                primitives::icosphere(DVec3::new(x, 0.0, 0.0), 1.0, 2),
                Material::Translucent(Translucent::new("m", medium.clone(), 0.8, 1.0)),
            );
        }
        let scene = b.build().unwrap();
        let w = scene_warnings(&scene, "sone".parse().unwrap());
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(!w[0].summary.contains('\n'));
        for k in 0..3 {
            assert!(w[0].summary.contains(&format!("`ball{k}`")), "{:?}", w[0]);
            assert!(w[0].detail.contains(&format!("`ball{k}` (")), "{:?}", w[0]);
        }
        assert_eq!(
            w[0].detail.matches("--method auto").count(),
            1,
            "{}",
            w[0].detail
        );
    }
}
