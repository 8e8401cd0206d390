//! The primitive shapes' descriptions converted to meshes (`[[shape]]` with `type = "box"`,
//! `"sphere"` or `"half_space"`), and what every shape description shares. Mesh files are read
//! by the loader (`load.rs`), which resolves their paths.

use glam::DVec3;

use super::desc::{BoxDesc, DescError, HalfSpaceDesc, ShapeCommon, ShapeDesc, SphereDesc};
use crate::geometry::{TriangleMesh, primitives};

/// Icosphere subdivisions when a sphere gives none.
const SPHERE_SUBDIVISIONS: u32 = 5;
/// Most icosphere subdivisions (5,242,880 triangles).
const SPHERE_MAX_SUBDIVISIONS: u32 = 9;
/// Grid subdivisions of a half-space's top face when it gives none.
const HALF_SPACE_SUBDIVISIONS: u32 = 32;
/// Most grid subdivisions of a half-space's top face.
const HALF_SPACE_MAX_SUBDIVISIONS: u32 = 1024;

impl ShapeDesc {
    /// The keys every shape has.
    pub fn common(&self) -> ShapeCommon {
        match self {
            ShapeDesc::Box(d) => d.common(),
            ShapeDesc::Sphere(d) => d.common(),
            ShapeDesc::HalfSpace(d) => d.common(),
            ShapeDesc::Obj(d) | ShapeDesc::Gltf(d) | ShapeDesc::Ply(d) => d.common(),
        }
    }

    /// The triangles a tessellated primitive will have (its subdivisions clamped to the
    /// most allowed, so that the count is finite before they are checked), `None` for the
    /// other shapes: the loader refuses, before generating any, primitives that would not fit
    /// in memory.
    pub fn tessellated_triangles(&self) -> Option<f64> {
        match self {
            ShapeDesc::Sphere(d) => {
                let s = d.subdivisions.unwrap_or(SPHERE_SUBDIVISIONS);
                Some(20.0 * 4f64.powi(s.min(SPHERE_MAX_SUBDIVISIONS) as i32))
            }
            ShapeDesc::HalfSpace(d) => {
                let s = d.subdivisions.unwrap_or(HALF_SPACE_SUBDIVISIONS);
                Some(2.0 * f64::from(s.min(HALF_SPACE_MAX_SUBDIVISIONS)).powi(2) + 10.0)
            }
            _ => None,
        }
    }
}

impl TryFrom<&BoxDesc> for TriangleMesh {
    type Error = DescError;

    /// The axis-aligned box `min..max` (finite, min < max in every axis).
    fn try_from(d: &BoxDesc) -> Result<TriangleMesh, DescError> {
        let (lo, hi) = (DVec3::from(d.min), DVec3::from(d.max));
        if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
            return Err(DescError::at(
                "max",
                format!(
                    "need min < max in every axis, got min {:?}, max {:?}",
                    d.min, d.max
                ),
            ));
        }
        Ok(primitives::cuboid(lo, hi))
    }
}

impl TryFrom<&SphereDesc> for TriangleMesh {
    type Error = DescError;

    /// The icosphere (finite positive radius, finite centre, at most 9 subdivisions).
    fn try_from(d: &SphereDesc) -> Result<TriangleMesh, DescError> {
        let c = DVec3::from(d.centre);
        if !(d.radius.is_finite() && d.radius > 0.0) {
            return Err(DescError::at(
                "radius",
                format!("radius must be finite and positive, got {}", d.radius),
            ));
        }
        if !c.is_finite() {
            return Err(DescError::at("centre", "centre must be finite"));
        }
        let s = d.subdivisions.unwrap_or(SPHERE_SUBDIVISIONS);
        if s > SPHERE_MAX_SUBDIVISIONS {
            return Err(DescError::at(
                "subdivisions",
                format!("at most 9 (5,242,880 triangles), got {s}"),
            ));
        }
        Ok(primitives::icosphere(c, d.radius, s))
    }
}

impl TryFrom<&HalfSpaceDesc> for TriangleMesh {
    type Error = DescError;

    /// The large box standing for a half-space (defaults: top 0, centre `[0, 0]`, size 1000,
    /// depth size / 2, 32 subdivisions).
    fn try_from(d: &HalfSpaceDesc) -> Result<TriangleMesh, DescError> {
        let size = d.size.unwrap_or(1000.0);
        let depth = d.depth.unwrap_or(0.5 * size);
        let top = d.top.unwrap_or(0.0);
        let centre = d.centre.unwrap_or([0.0, 0.0]);
        let sub = d.subdivisions.unwrap_or(HALF_SPACE_SUBDIVISIONS);
        for (name, val) in [("size", size), ("depth", depth)] {
            if !(val.is_finite() && val > 0.0) {
                return Err(DescError::at(
                    name,
                    format!("{name} must be finite and positive, got {val}"),
                ));
            }
        }
        if !(top.is_finite() && centre.iter().all(|c| c.is_finite())) {
            return Err(DescError::at("top", "top and centre must be finite"));
        }
        if sub == 0 || sub > HALF_SPACE_MAX_SUBDIVISIONS {
            return Err(DescError::at(
                "subdivisions",
                format!("must be in 1..=1024, got {sub}"),
            ));
        }
        Ok(primitives::half_space(top, centre, size, depth, sub))
    }
}
