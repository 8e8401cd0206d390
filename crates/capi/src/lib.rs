//! The C ABI of het-bssrdf, for C and C++ renderers: prepare a material once
//! ([`hb_material_new`]), estimate the homogeneous coefficients of a pair of surface points
//! over the renderer's own geometry and textures ([`hb_estimate`], through two callbacks), and
//! evaluate the separable BSSRDF S ([`hb_eval`], `bssrdf_core::SeparableBssrdf`) or the radial
//! profile R ([`hb_profile`]). The header `include/het_bssrdf.h` is generated from this file
//! by cbindgen (`tests/header.rs` regenerates it and fails when the checked-in copy differs);
//! `examples/pair.c` is a complete C program.
//!
//! # Conventions
//! The same as the Rust crates': lengths in scene units, coefficients in 1/length, colour
//! channels in linear RGB (`[3]` arrays), normals and directions unit vectors pointing out of
//! the medium, S in 1/(length²·sr). Every function returns an [`HbStatus`]; on an error,
//! [`hb_last_error`] gives the message (per thread) and the outputs are left untouched. No
//! function panics across the boundary: a panic inside becomes [`HbStatus::Panic`].
//!
//! # Threads
//! A material is immutable once made: [`hb_estimate`], [`hb_eval`] and [`hb_profile`] may be
//! called on one material from many threads at once (the callbacks then must be thread-safe
//! for their `user` data). Results are deterministic for a given `seed`.
#![deny(missing_docs)]

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

use bssrdf_core::glam::DVec3;
use bssrdf_core::{
    Coefficients, Crossing, ParamError, ProfileFamily, ProfileModel, Rgb, Scattering,
    SeparableBssrdf,
};
use het_estimate::{
    CoefficientField, Estimator, PreparedEstimator, SplitMix64, SurfacePoint, SurfaceQuery,
};

/// What a call did.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HbStatus {
    /// Success: the outputs are written.
    Ok = 0,
    /// A required pointer was null.
    NullPointer = 1,
    /// A name was not valid UTF-8 or not a known name, or a number was out of its range
    /// ([`hb_last_error`] names it).
    InvalidArgument = 2,
    /// A bug inside the library (it panicked); the message is in [`hb_last_error`].
    Panic = 3,
}

/// A point on the renderer's surface: what [`HbProjectFn`] returns and [`HbCoefficientsFn`]
/// reads.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HbSurfacePoint {
    /// Position (scene units).
    pub position: [f64; 3],
    /// Unit shading normal, pointing out of the medium.
    pub normal: [f64; 3],
    /// The renderer's own data for the lookup (a triangle id, a texture coordinate index, …);
    /// the library copies it and never reads it.
    pub tag: u64,
}

/// Where light crosses the boundary, for [`hb_eval`]: the surface point, its unit normal (out
/// of the medium) and the unit direction outside, pointing away from the surface (toward the
/// light at x_i, toward the viewer at x_o).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HbCrossing {
    /// The surface point (scene units).
    pub point: [f64; 3],
    /// Unit normal, out of the medium.
    pub normal: [f64; 3],
    /// Unit direction outside, away from the surface.
    pub direction: [f64; 3],
}

/// Absorption and scattering coefficients per colour channel (1/length).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HbCoefficients {
    /// σa per channel.
    pub sigma_a: [f64; 3],
    /// σs per channel.
    pub sigma_s: [f64; 3],
}

/// Projects onto the object being shaded: trace two rays from `origin`, along `+dir` and
/// `-dir` (`dir` a unit vector), write the nearer hit on the object to `out` and return true;
/// return false when neither ray hits it (`het_estimate::SurfaceQuery::project`). `origin`
/// and `dir` point to three doubles each. Nullable (NULL is refused by [`hb_estimate`]).
pub type HbProjectFn = Option<
    unsafe extern "C" fn(
        user: *mut c_void,
        origin: *const f64,
        dir: *const f64,
        out: *mut HbSurfacePoint,
    ) -> bool,
>;

/// Writes σa and σs per channel at the surface point `p` to `out` (finite, ≥ 0). Nullable
/// (NULL is refused by [`hb_estimate`]).
pub type HbCoefficientsFn = Option<
    unsafe extern "C" fn(user: *mut c_void, p: *const HbSurfacePoint, out: *mut HbCoefficients),
>;

/// The renderer's object for [`hb_estimate`]: its two callbacks and the pointer they receive.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HbSurface {
    /// Passed unchanged to both callbacks.
    pub user: *mut c_void,
    /// The projection (required).
    pub project: HbProjectFn,
    /// The coefficient lookup (required).
    pub coefficients: HbCoefficientsFn,
}

/// A prepared material: the separable BSSRDF and the estimator, resolved once. Opaque; made by
/// [`hb_material_new`], freed by [`hb_material_free`].
pub struct HbMaterial {
    bssrdf: SeparableBssrdf,
    estimator: PreparedEstimator,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs `f`, turning its error and any panic into a status and a message.
fn guarded(f: impl FnOnce() -> Result<(), (HbStatus, String)>) -> HbStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => HbStatus::Ok,
        Ok(Err((status, message))) => {
            set_error(&message);
            status
        }
        Err(panic) => {
            let message = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_error(&format!("internal error: {message}"));
            HbStatus::Panic
        }
    }
}

fn invalid(e: ParamError) -> (HbStatus, String) {
    (HbStatus::InvalidArgument, e.to_string())
}

/// A reference from a pointer, or the null-pointer error naming `what`.
///
/// # Safety
/// `p` is null or valid for reads of `T` for the call.
unsafe fn deref<'a, T>(p: *const T, what: &str) -> Result<&'a T, (HbStatus, String)> {
    // SAFETY: the caller guarantees `p` is null or valid.
    unsafe { p.as_ref() }.ok_or_else(|| (HbStatus::NullPointer, format!("`{what}` is null")))
}

/// A name argument as `&str`.
///
/// # Safety
/// `p` is null or a NUL-terminated string valid for the call.
unsafe fn name<'a>(p: *const c_char, what: &str) -> Result<&'a str, (HbStatus, String)> {
    if p.is_null() {
        return Err((HbStatus::NullPointer, format!("`{what}` is null")));
    }
    // SAFETY: non-null, and the caller guarantees a NUL-terminated string.
    unsafe { CStr::from_ptr(p) }.to_str().map_err(|_| {
        (
            HbStatus::InvalidArgument,
            format!("`{what}` is not valid UTF-8"),
        )
    })
}

fn vec3(v: [f64; 3]) -> DVec3 {
    DVec3::from_array(v)
}

impl From<HbCoefficients> for Coefficients {
    fn from(c: HbCoefficients) -> Self {
        Coefficients::new(Rgb(c.sigma_a), Rgb(c.sigma_s))
    }
}

impl From<Coefficients> for HbCoefficients {
    fn from(c: Coefficients) -> Self {
        HbCoefficients {
            sigma_a: c.sigma_a.0,
            sigma_s: c.sigma_s.0,
        }
    }
}

impl From<HbCrossing> for Crossing {
    fn from(c: HbCrossing) -> Self {
        Crossing::new(vec3(c.point), vec3(c.normal), vec3(c.direction))
    }
}

impl SurfacePoint for HbSurfacePoint {
    #[inline]
    fn position(&self) -> DVec3 {
        vec3(self.position)
    }
    #[inline]
    fn normal(&self) -> DVec3 {
        vec3(self.normal)
    }
}

/// [`HbSurface`] with both callbacks checked present.
struct Callbacks {
    user: *mut c_void,
    project: unsafe extern "C" fn(*mut c_void, *const f64, *const f64, *mut HbSurfacePoint) -> bool,
    coefficients: unsafe extern "C" fn(*mut c_void, *const HbSurfacePoint, *mut HbCoefficients),
}

impl SurfaceQuery for Callbacks {
    type Point = HbSurfacePoint;
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<HbSurfacePoint> {
        let (o, d) = (origin.to_array(), dir.to_array());
        let mut out = HbSurfacePoint {
            position: [0.0; 3],
            normal: [0.0; 3],
            tag: 0,
        };
        // SAFETY: the renderer's callback, given valid pointers to three doubles each and to
        // an output point, as `HbProjectFn` documents.
        let hit = unsafe { (self.project)(self.user, o.as_ptr(), d.as_ptr(), &mut out) };
        hit.then_some(out)
    }
}

impl CoefficientField<HbSurfacePoint> for Callbacks {
    fn coefficients(&self, p: &HbSurfacePoint) -> Coefficients {
        let mut out = HbCoefficients::default();
        // SAFETY: the renderer's callback, given valid pointers as `HbCoefficientsFn`
        // documents.
        unsafe { (self.coefficients)(self.user, p, &mut out) };
        out.into()
    }
}

/// Prepares a material: the profile `model` (`"dipole"`, `"pbd"`, `"better-dipole"`,
/// `"tabulated"`), the orders counted (`scattering`: `"single"`,
/// `"multiple"`, `"all"`), the estimator (`"jensen-in"`, `"jensen-out"`, `"endpoints"`,
/// `"segment"`, `"sone"`, `"kernel"`, with default parameters), the Henyey–Greenstein mean
/// cosine `g` (|g| < 1) and the relative index of refraction `eta` (in [1, 3]; at most 1.6
/// for `"tabulated"`). Writes the new material to `*out`; free it with [`hb_material_free`].
/// Costs up to a few milliseconds: once per material.
///
/// # Safety
/// The three names are NUL-terminated strings; `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn hb_material_new(
    model: *const c_char,
    scattering: *const c_char,
    estimator: *const c_char,
    g: f64,
    eta: f64,
    out: *mut *mut HbMaterial,
) -> HbStatus {
    guarded(|| {
        if out.is_null() {
            return Err((HbStatus::NullPointer, "`out` is null".into()));
        }
        // SAFETY: the caller's strings (checked for null inside).
        let (model, scattering, estimator) = unsafe {
            (
                name(model, "model")?,
                name(scattering, "scattering")?,
                name(estimator, "estimator")?,
            )
        };
        let model: ProfileModel = model
            .parse()
            .map_err(|e: bssrdf_core::UnknownName| invalid(e.into()))?;
        let scattering: Scattering = scattering
            .parse()
            .map_err(|e: bssrdf_core::UnknownName| invalid(e.into()))?;
        let estimator: Estimator = estimator
            .parse()
            .map_err(|e: bssrdf_core::UnknownName| invalid(e.into()))?;
        let material = HbMaterial {
            bssrdf: SeparableBssrdf::new(model, scattering, g, eta).map_err(invalid)?,
            estimator: estimator.prepare(g, eta).map_err(invalid)?,
        };
        // SAFETY: `out` is non-null and valid for a write (the caller's guarantee).
        unsafe { *out = Box::into_raw(Box::new(material)) };
        Ok(())
    })
}

/// Frees a material made by [`hb_material_new`]; null is ignored.
///
/// # Safety
/// `material` is null or a material from [`hb_material_new`] not yet freed, used by no other
/// call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn hb_material_free(material: *mut HbMaterial) {
    if !material.is_null() {
        // SAFETY: made by `Box::into_raw` in `hb_material_new`, freed once (the caller's
        // guarantee).
        drop(unsafe { Box::from_raw(material) });
    }
}

/// Estimates the homogeneous coefficients between the incident point `x_i` and the exitant
/// point `x_o` on the renderer's object `surface` (`het_estimate::PreparedEstimator::estimate`),
/// with random numbers from `seed` (the same seed gives the same result). Writes them to
/// `out`, always within [0, 1e12] per unit length.
///
/// # Safety
/// Every pointer is valid for the call; the callbacks behave as [`HbProjectFn`] and
/// [`HbCoefficientsFn`] document.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn hb_estimate(
    material: *const HbMaterial,
    surface: *const HbSurface,
    x_i: *const HbSurfacePoint,
    x_o: *const HbSurfacePoint,
    seed: u64,
    out: *mut HbCoefficients,
) -> HbStatus {
    guarded(|| {
        // SAFETY: the caller's pointers (checked for null inside).
        let (material, surface, x_i, x_o) = unsafe {
            (
                deref(material, "material")?,
                deref(surface, "surface")?,
                deref(x_i, "x_i")?,
                deref(x_o, "x_o")?,
            )
        };
        if out.is_null() {
            return Err((HbStatus::NullPointer, "`out` is null".into()));
        }
        let (Some(project), Some(coefficients)) = (surface.project, surface.coefficients) else {
            return Err((
                HbStatus::NullPointer,
                "`surface` needs both `project` and `coefficients`".into(),
            ));
        };
        let callbacks = Callbacks {
            user: surface.user,
            project,
            coefficients,
        };
        let mut rng = SplitMix64::new(seed);
        let est = material
            .estimator
            .estimate(&callbacks, &callbacks, x_i, x_o, &mut rng);
        // SAFETY: non-null and valid for a write (the caller's guarantee).
        unsafe { *out = est.coefficients.into() };
        Ok(())
    })
}

/// Evaluates S(x_i, ω_i; x_o, ω_o) per channel (1/(length²·sr)) at the coefficients `c`
/// (`bssrdf_core::SeparableBssrdf::eval`: the profile, the Fresnel transmissions at both ends,
/// their normalisation c = 1 − 2C₁(1/η), the tabulated profile's angular coupling), light
/// entering at `incident` and leaving at `exitant`. Writes three values to `out`.
///
/// # Safety
/// Every pointer is valid for the call; `out` for three doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn hb_eval(
    material: *const HbMaterial,
    c: *const HbCoefficients,
    incident: *const HbCrossing,
    exitant: *const HbCrossing,
    out: *mut f64,
) -> HbStatus {
    guarded(|| {
        // SAFETY: the caller's pointers (checked for null inside).
        let (material, c, incident, exitant) = unsafe {
            (
                deref(material, "material")?,
                deref(c, "c")?,
                deref(incident, "incident")?,
                deref(exitant, "exitant")?,
            )
        };
        if out.is_null() {
            return Err((HbStatus::NullPointer, "`out` is null".into()));
        }
        let s = material
            .bssrdf
            .eval(&(*c).into(), &(*incident).into(), &(*exitant).into())
            .map_err(invalid)?;
        // SAFETY: non-null and valid for three doubles (the caller's guarantee).
        unsafe { std::ptr::copy_nonoverlapping(s.0.as_ptr(), out, 3) };
        Ok(())
    })
}

/// Evaluates the radial profile R(r) per channel (1/length²; `bssrdf_core::RadialProfile`,
/// no Fresnel factor and no angular normalisation) at distance `r` ≥ 0 and coefficients `c`.
/// Writes three values to `out`.
///
/// # Safety
/// Every pointer is valid for the call; `out` for three doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn hb_profile(
    material: *const HbMaterial,
    c: *const HbCoefficients,
    r: f64,
    out: *mut f64,
) -> HbStatus {
    guarded(|| {
        // SAFETY: the caller's pointers (checked for null inside).
        let (material, c) = unsafe { (deref(material, "material")?, deref(c, "c")?) };
        if out.is_null() {
            return Err((HbStatus::NullPointer, "`out` is null".into()));
        }
        bssrdf_core::error::check_non_negative("r", r).map_err(invalid)?;
        let family: &ProfileFamily = material.bssrdf.family();
        let profile = family
            .profile_rgb(Rgb(c.sigma_a), Rgb(c.sigma_s))
            .map_err(invalid)?;
        let values = profile.eval_rgb(r).0;
        // SAFETY: non-null and valid for three doubles (the caller's guarantee).
        unsafe { std::ptr::copy_nonoverlapping(values.as_ptr(), out, 3) };
        Ok(())
    })
}

/// The message of the last failed call on this thread (UTF-8, NUL-terminated; empty when none
/// failed). Valid until the next failing call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn hb_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}
