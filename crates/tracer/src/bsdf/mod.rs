//! Surface scattering: the microfacet distribution ([`microfacet`]), the rough dielectric
//! boundary of translucent materials ([`dielectric`]) and the directional transmittance the
//! BSSRDF takes from it ([`transmittance`]), and the rough diffuse reflector of opaque
//! materials ([`diffuse`]).
//!
//! Everything here works in the local frame of the macro-surface (normal `+z`) and knows no
//! scene types; the integrators build the frame ([`Frame`]) at each hit.

pub mod dielectric;
pub mod diffuse;
pub mod microfacet;
pub mod transmittance;

pub use dielectric::{DielectricSample, Lobe, RoughDielectric};
pub use diffuse::oren_nayar;
pub use microfacet::{SMOOTH_ALPHA, TrowbridgeReitz, alpha_from_roughness};
pub use transmittance::TransmittanceTable;

use glam::DVec3;

/// An orthonormal frame `(t, b, n)` about a unit normal `n` (Duff17's basis): world ↔ local
/// (`n` is local `+z`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Frame {
    /// The frame about the unit normal `n`.
    #[inline]
    pub fn new(n: DVec3) -> Self {
        let (t, b) = het_estimate::frame::orthonormal_basis(n);
        Self { t, b, n }
    }

    /// `w` in local coordinates.
    #[inline]
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.t), w.dot(self.b), w.dot(self.n))
    }

    /// The world vector of local `l`.
    #[inline]
    pub fn to_world(&self, l: DVec3) -> DVec3 {
        l.x * self.t + l.y * self.b + l.z * self.n
    }
}
