//! How large a translucent object is against the distance light spreads in its medium: the
//! diffusion length and the transport mean free path (JMLH01), and the threshold under which
//! an object is too small for a half-space profile. `--method auto`, the shape correction's
//! `auto` and the scene warnings decide with it.

use crate::scene::Scene;

/// Objects whose thinnest side spans fewer diffusion lengths (or transport mean free paths,
/// whichever is longer) than this are too small for a half-space profile ([`is_optically_small`]), which the scene warnings
/// report.
pub const SMALL_OBJECT_DIFFUSION_LENGTHS: f64 = 5.0;

/// How far light spreads in a medium with coefficients `c`: the longest, over the channels, of
/// the diffusion length 1/σtr (σtr = √(3σa σt'), JMLH01) and the transport mean free path
/// 1/σt' (σt' = σa + (1 − g)σs), and whether it is the diffusion length. ∞ where a channel
/// scatters without absorbing; 0 for a medium that neither absorbs nor scatters.
pub(crate) fn light_reach(c: het_estimate::Coefficients, g: f64) -> (f64, bool) {
    (0..3)
        .map(|ch| {
            let (a, s) = (c.sigma_a[ch], c.sigma_s[ch] * (1.0 - g));
            let sigma_tp = a + s;
            let sigma_tr = (3.0 * a * sigma_tp).sqrt();
            let diffusion = if sigma_tr > 0.0 { 1.0 / sigma_tr } else { 0.0 };
            let transport = if sigma_tp > 0.0 { 1.0 / sigma_tp } else { 0.0 };
            if sigma_tp > 0.0 && sigma_tr == 0.0 {
                (f64::INFINITY, true)
            } else {
                (diffusion.max(transport), diffusion >= transport)
            }
        })
        .fold((0.0, true), |acc, x| if x.0 > acc.0 { x } else { acc })
}

/// Whether translucent object `object` is too small for a half-space profile: its bounding
/// box's thinnest side is shorter than [`SMALL_OBJECT_DIFFUSION_LENGTHS`] times the longer of
/// the diffusion length and the transport mean free path of its most translucent part
/// (`light_reach` at the field's smallest coefficients). `--method auto` path-traces such
/// objects, and the shape correction's `auto` corrects those a BSSRDF renders. False for an
/// object that is not translucent.
pub fn is_optically_small(scene: &Scene, object: u32) -> bool {
    let Some(t) = scene
        .objects()
        .get(object as usize)
        .and_then(|o| o.material.translucent())
    else {
        return false;
    };
    let (lo, hi) = scene.geometry().object_bounds(object);
    let thinnest = (hi - lo).min_element();
    let (longest, _) = light_reach(t.medium.field_bounds().min, t.g);
    longest > 0.0 && thinnest.is_finite() && thinnest < SMALL_OBJECT_DIFFUSION_LENGTHS * longest
}
