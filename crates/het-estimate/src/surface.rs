//! The surface-query trait: what the estimators need to know about the geometry.

use glam::DVec3;

use crate::local_surface::Curvature;
use crate::uv_chart::UvChart;

/// A point on the surface of the object being shaded.
pub trait SurfacePoint {
    /// Position in scene units.
    fn position(&self) -> DVec3;
    /// Unit shading normal, pointing out of the medium.
    fn normal(&self) -> DVec3;
    /// Unit geometric normal (of the surface itself, not interpolated), pointing out of the
    /// medium. Probe sampling's density uses it ([`crate::probe`]); it defaults to
    /// [`SurfacePoint::normal`], which is exact for surfaces without normal interpolation.
    fn geometric_normal(&self) -> DVec3 {
        self.normal()
    }
}

/// Geometric queries restricted to the object being shaded.
///
/// Implementations trace against their own acceleration structure; the estimators call
/// [`SurfaceQuery::project`] once per averaging sample and never allocate.
///
/// # f32 geometry
/// Points cross the trait in f64, because the estimators' geometry (chords, ellipses, widths
/// down to 1e-6 of the coordinates) needs it. A renderer whose geometry is f32 converts on
/// every call, and that costs nothing measurable: through an 81,920-triangle BVH one projection
/// takes 1.59 µs from f64 points and 1.58 µs after an f32 round trip of its arguments
/// (`cargo bench --bench averaging -- project`, ±5 %). The tracer itself stores its BVH in f32.
pub trait SurfaceQuery {
    /// The renderer's surface-point type (it may carry triangle ids, UVs, …, for the
    /// coefficient lookup).
    type Point: SurfacePoint;

    /// Traces two rays from `origin`, one along `+dir` and one along `-dir` (`dir` is a unit
    /// vector: the normal of the averaging plane), and returns the nearer hit on the object
    /// being shaded; `None` when neither ray hits it (paper §3.2, Figure 3).
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Self::Point>;

    /// [`SurfaceQuery::project`], told that the nearer hit usually lies within `reach` of
    /// `origin` (the estimators pass the size of the region the point belongs to: a surface
    /// departs from an averaging plane through two of its points by about that much at most).
    /// The answer must be `project`'s: a surface may search both rays within `reach` first
    /// (short rays visit few nodes of a BVH) and beyond it only where neither hits there. The
    /// default calls `project`.
    #[inline]
    fn project_within(&self, origin: DVec3, dir: DVec3, reach: f64) -> Option<Self::Point> {
        let _ = reach;
        self.project(origin, dir)
    }

    /// Optional capability: where [`SurfaceQuery::project`]'s hit lies, when the surface can
    /// say it without building a point (an analytic shape, such as a box, whose crossing is a
    /// plane equation rather than a traversal). The estimators ask it for fields defined in
    /// space ([`crate::CoefficientField::averaged_at_point`]), which need no more than the
    /// position, and call `project` on [`Projected::Undecided`]. The position may sit a
    /// rounding-sized step inside the surface, so that a face lying on a texture's cell
    /// boundary reads the medium behind it. The default is always `Undecided`.
    #[inline]
    fn project_position(&self, origin: DVec3, dir: DVec3) -> Projected {
        let _ = (origin, dir);
        Projected::Undecided
    }

    /// [`SurfaceQuery::project_position`] for several origins along one direction, into `out`
    /// (as long as `origins`): the estimators hand over a stage's points together, so that a
    /// surface can do the direction's share of the work once. The default asks
    /// `project_position` for each.
    #[inline]
    fn project_positions(&self, origins: &[DVec3], dir: DVec3, out: &mut [Projected]) {
        for (o, r) in origins.iter().zip(out.iter_mut()) {
            *r = self.project_position(*o, dir);
        }
    }

    /// Optional capability: the texture coordinates around `p` as an affine map (for a mesh,
    /// the map of `p`'s triangle, taken at `p`), for fields read through texture coordinates
    /// ([`crate::FieldCapabilities::reads_uv`]). The estimators build the chart of a flat
    /// pair's averaging region from the charts at x_i and x_o ([`UvChart::between`]) and
    /// average such a field in constant time through it; `None` (the default: no texture
    /// coordinates, or a degenerate triangle) means the region is sampled.
    fn uv_chart(&self, p: &Self::Point) -> Option<UvChart> {
        let _ = p;
        None
    }

    /// Optional capability: the surface's curvature at `p` ([`Curvature`]: the second
    /// fundamental form as a world-space tensor, positive on convex bodies). The estimators
    /// fit a quadric to the pair's two ends with it ([`crate::local_surface`]), which lets
    /// them prefilter on curved surfaces and place sample points on the quadric instead of
    /// projecting them by rays, wherever the quadric's error bound allows
    /// ([`crate::Flatness`]). `None` (the default) is read as flat between the ends, the
    /// normals' disagreement with that counted as the model's error: correct, but it admits
    /// only nearly flat pairs.
    fn curvature(&self, p: &Self::Point) -> Option<Curvature> {
        let _ = p;
        None
    }
}

/// The answer of [`SurfaceQuery::project_position`] (a position, by default), or of any
/// shortcut to [`SurfaceQuery::project`] that may not settle every line (the tracer's boxes
/// answer with their hits too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projected<T = DVec3> {
    /// The nearer hit (for `project_position`, its position, scene units).
    At(T),
    /// Neither ray hits the object.
    Miss,
    /// Not known without [`SurfaceQuery::project`].
    Undecided,
}

impl<S: SurfaceQuery + ?Sized> SurfaceQuery for &S {
    type Point = S::Point;
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Self::Point> {
        (**self).project(origin, dir)
    }
    fn project_within(&self, origin: DVec3, dir: DVec3, reach: f64) -> Option<Self::Point> {
        (**self).project_within(origin, dir, reach)
    }
    fn project_position(&self, origin: DVec3, dir: DVec3) -> Projected {
        (**self).project_position(origin, dir)
    }
    fn project_positions(&self, origins: &[DVec3], dir: DVec3, out: &mut [Projected]) {
        (**self).project_positions(origins, dir, out)
    }
    fn uv_chart(&self, p: &Self::Point) -> Option<UvChart> {
        (**self).uv_chart(p)
    }
}
