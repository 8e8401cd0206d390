//! Coefficient fields: σa or σs as linear RGB over an object (1/scene-unit), and
//! [`MediumField`], the pair a translucent material is made of: σa and σs, or an artist's
//! colour and mean free path inverted to σa and σs ([`MediumField::artist`], [`InvertAt`],
//! `docs/artist-parameters.md`).
//!
//! A [`Field`] is one of a closed set, matched once per lookup (a predictable branch):
//! * constant (grey or RGB);
//! * a procedural two-valued pattern (stripe or check, the very definitions and code of
//!   [`het_estimate::pattern`]) through a [`PlanarProjection`];
//! * an image texture through a planar projection (defined in the volume, constant along the
//!   axis) or through the mesh's texture coordinates (defined on the surface only: usable by
//!   the BSSRDF methods, not by the volumetric path tracer).
//!
//! Image placement for the planar projection: the image covers `s ∈ [−W/2, W/2]`,
//! `t ∈ [−H/2, H/2]` (`size = [W, H]`, scene units) centred on the projection origin; image
//! columns run along `+s`, rows run along `−t` (row 0 at `t = +H/2`), so that an image seen
//! from the `+axis` side (for axis z: from above, x right, y up) appears upright. For texture
//! coordinates, `(u, v)` with `v` up (OBJ convention) reads the image at `(u, 1 − v)`.

pub mod area_table;
mod artist;
mod texture;
mod texture_mapping;

pub use artist::{ArtistMap, InvertAt, MFP_FLOOR_FRACTION};
pub use texture::{Filter, TEXTURE_LIMIT_VAR, Texture, Wrap, check_decoded_size, decoder_limit_mb};
pub use texture_mapping::{Axis, PlanarProjection};

use std::sync::Arc;

use bssrdf_core::Rgb;
use glam::{DVec2, DVec3};
use het_estimate::pattern::{BinaryPattern, Check, Stripe};
use het_estimate::prefilter::{PlaneFootprint, check_fraction, stripe_fraction};
use het_estimate::{
    CoefficientField, Coefficients, FieldBounds, FieldCapabilities, PlanarEllipse, UvChart,
};

use crate::error::FieldError;
use crate::geometry::Hit;

/// A procedural two-valued pattern from [`het_estimate::pattern`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    /// Parallel bands.
    Stripe(Stripe),
    /// Checkerboard.
    Check(Check),
}

impl Pattern {
    /// 0 or 1 at `(s, t)`.
    #[inline]
    pub fn select(&self, s: f64, t: f64) -> usize {
        match self {
            Pattern::Stripe(p) => p.select(s, t),
            Pattern::Check(p) => p.select(s, t),
        }
    }

    /// The weighted fraction of `fp` where the pattern selects 1, in closed form
    /// ([`het_estimate::prefilter`]); `None` where the closed form declines.
    #[inline]
    pub fn fraction(&self, fp: &PlaneFootprint) -> Option<f64> {
        match self {
            Pattern::Stripe(p) => stripe_fraction(p, fp),
            Pattern::Check(p) => check_fraction(p, fp),
        }
    }
}

/// Where an image is read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ImageMapping {
    /// Planar projection; the image spans `size = [W, H]` scene units centred on the
    /// projection origin (see the module docs).
    Planar {
        /// The projection.
        projection: PlanarProjection,
        /// World size `[W, H]` of the whole image.
        size: [f64; 2],
    },
    /// The mesh's texture coordinates (surface only).
    Uv,
}

/// An image-textured field: `value = scale ⊙ texel(…)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageField {
    /// The decoded texture (shared between fields using the same file).
    pub texture: Arc<Texture>,
    /// Where it is read.
    pub mapping: ImageMapping,
    /// Outside `[0, 1]²`.
    pub wrap: Wrap,
    /// Reconstruction.
    pub filter: Filter,
    /// Per-channel multiplier (1/scene-unit per texel unit).
    pub scale: Rgb,
}

impl ImageField {
    #[inline]
    fn lookup(&self, u: f64, v_down: f64) -> Rgb {
        let t = self.texture.lookup(u, v_down, self.wrap, self.filter);
        Rgb(t) * self.scale
    }

    /// The prefiltered uniform average over the ellipse `e` as it lies in its plane, for a
    /// planar mapping: the ellipse's footprint in texel space averaged through the texture's
    /// summed-area table ([`area_table`]; nearest and bilinear filtering both averaged as
    /// nearest, error bounds there). `None` for UV mapping (the footprint follows the UV
    /// Jacobian, which needs the surface: [`ImageField::ellipse_average_in_chart`]) and where
    /// the table declines.
    pub fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Rgb> {
        let ImageMapping::Planar { projection, size } = self.mapping else {
            return None;
        };
        let fp = projection.footprint(e);
        let (w, h) = (self.texture.width as f64, self.texture.height as f64);
        // Texel coordinates: x = (s/W + ½)·w, y = (½ − t/H)·h (rows run along −t).
        let (kx, ky) = (w / size[0], -h / size[1]);
        let te = area_table::TexelEllipse {
            centre: [
                (fp.centre.x / size[0] + 0.5) * w,
                (0.5 - fp.centre.y / size[1]) * h,
            ],
            axis_u: [fp.axis_u.x * kx, fp.axis_u.y * ky],
            axis_v: [fp.axis_v.x * kx, fp.axis_v.y * ky],
        };
        let avg = self.texture.area_table().ellipse_average(&te, self.wrap)?;
        Some(Rgb(avg) * self.scale)
    }

    /// The prefiltered uniform average over the ellipse `e` for a UV mapping, through `chart`,
    /// the texture coordinates over the ellipse's plane (the UV Jacobian at its centre,
    /// [`het_estimate::UvChart`]): the ellipse's footprint in texel space averaged through the
    /// summed-area table, as for a planar mapping. `None` for a planar mapping (see
    /// [`ImageField::ellipse_average`]) and where the table declines.
    pub fn ellipse_average_in_chart(&self, e: &PlanarEllipse, chart: &UvChart) -> Option<Rgb> {
        if self.mapping != ImageMapping::Uv {
            return None;
        }
        let (w, h) = (self.texture.width as f64, self.texture.height as f64);
        let (c, a, b) = (
            chart.uv_at(e.centre),
            chart.map_vector(e.semi_major),
            chart.map_vector(e.semi_minor),
        );
        // Texel coordinates: x = u·w, y = (1 − v)·h (rows run along −v), as `at` reads them.
        let te = area_table::TexelEllipse {
            centre: [c.x * w, (1.0 - c.y) * h],
            axis_u: [a.x * w, -a.y * h],
            axis_v: [b.x * w, -b.y * h],
        };
        let avg = self.texture.area_table().ellipse_average(&te, self.wrap)?;
        Some(Rgb(avg) * self.scale)
    }

    #[inline]
    fn at(&self, p: DVec3, uv: DVec2) -> Rgb {
        match self.mapping {
            ImageMapping::Planar { projection, size } => {
                let (s, t) = projection.st(p);
                self.lookup(s / size[0] + 0.5, 0.5 - t / size[1])
            }
            ImageMapping::Uv => self.lookup(uv.x, 1.0 - uv.y),
        }
    }
}

/// σa or σs over an object, linear RGB in 1/scene-unit.
#[derive(Debug, Clone, PartialEq)]
pub enum Field {
    /// The same value everywhere.
    Constant(Rgb),
    /// `values[pattern.select(s, t)]`.
    Pattern {
        /// The pattern.
        pattern: Pattern,
        /// Value where the pattern selects 0, and where it selects 1.
        values: [Rgb; 2],
        /// How points map to the pattern's plane.
        projection: PlanarProjection,
    },
    /// An image texture.
    Image(ImageField),
}

fn check_value(what: impl Into<String>, v: Rgb) -> Result<Rgb, FieldError> {
    if v.is_finite() && v.min_component() >= 0.0 {
        Ok(v)
    } else {
        Err(FieldError::BadValue {
            what: what.into(),
            value: v.0,
        })
    }
}

fn check_length(what: &'static str, v: f64) -> Result<f64, FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(FieldError::BadLength { what, value: v })
    }
}

impl Field {
    /// A constant field (`value` finite and non-negative).
    pub fn constant(value: Rgb) -> Result<Field, FieldError> {
        Ok(Field::Constant(check_value("value", value)?))
    }

    /// Stripes of width `width` varying along the direction at `angle_radians` in the
    /// projection plane ([`het_estimate::pattern::Stripe`]).
    pub fn stripe(
        width: f64,
        angle_radians: f64,
        values: [Rgb; 2],
        projection: PlanarProjection,
    ) -> Result<Field, FieldError> {
        check_length("stripe width", width)?;
        if !angle_radians.is_finite() {
            return Err(FieldError::Other(format!(
                "stripe angle must be finite, got {angle_radians}"
            )));
        }
        Ok(Field::Pattern {
            pattern: Pattern::Stripe(Stripe::new(width, angle_radians)),
            values: [
                check_value("values[0]", values[0])?,
                check_value("values[1]", values[1])?,
            ],
            projection,
        })
    }

    /// A checkerboard of cell side `width` ([`het_estimate::pattern::Check`]).
    pub fn check(
        width: f64,
        values: [Rgb; 2],
        projection: PlanarProjection,
    ) -> Result<Field, FieldError> {
        check_length("check width", width)?;
        Ok(Field::Pattern {
            pattern: Pattern::Check(Check { width }),
            values: [
                check_value("values[0]", values[0])?,
                check_value("values[1]", values[1])?,
            ],
            projection,
        })
    }

    /// An image field (`scale` finite, non-negative; planar `size` finite, positive).
    pub fn image(
        texture: Arc<Texture>,
        mapping: ImageMapping,
        wrap: Wrap,
        filter: Filter,
        scale: Rgb,
    ) -> Result<Field, FieldError> {
        if let ImageMapping::Planar { size, .. } = mapping {
            check_length("image width (size[0])", size[0])?;
            check_length("image height (size[1])", size[1])?;
        }
        Ok(Field::Image(ImageField {
            texture,
            mapping,
            wrap,
            filter,
            scale: check_value("scale", scale)?,
        }))
    }

    /// The field multiplied by `k ≥ 0` (unit conversion).
    pub fn scaled(self, k: f64) -> Field {
        self.scaled_rgb(Rgb::splat(k))
    }

    /// The field multiplied channel-wise by `k ≥ 0` (an artist's radius scale).
    pub fn scaled_rgb(self, k: Rgb) -> Field {
        match self {
            Field::Constant(v) => Field::Constant(v * k),
            Field::Pattern {
                pattern,
                values,
                projection,
            } => Field::Pattern {
                pattern,
                values: [values[0] * k, values[1] * k],
                projection,
            },
            Field::Image(mut f) => {
                f.scale *= k;
                Field::Image(f)
            }
        }
    }

    /// The value at a surface point `p` with texture coordinates `uv`.
    #[inline]
    pub fn eval(&self, p: DVec3, uv: DVec2) -> Rgb {
        match self {
            Field::Constant(v) => *v,
            Field::Pattern {
                pattern,
                values,
                projection,
            } => {
                let (s, t) = projection.st(p);
                values[pattern.select(s, t)]
            }
            Field::Image(f) => f.at(p, uv),
        }
    }

    /// [`Field::eval`] at each of `ps` with no texture coordinates, into `out` (as long as
    /// `ps`): for fields defined in space ([`Field::is_volumetric`]), the kind matched once.
    pub fn eval_points(&self, ps: &[DVec3], out: &mut [Rgb]) {
        match self {
            Field::Constant(v) => out.fill(*v),
            Field::Pattern {
                pattern,
                values,
                projection,
            } => {
                for (p, o) in ps.iter().zip(out.iter_mut()) {
                    let (s, t) = projection.st(*p);
                    *o = values[pattern.select(s, t)];
                }
            }
            Field::Image(f) => {
                for (p, o) in ps.iter().zip(out.iter_mut()) {
                    *o = f.at(*p, DVec2::ZERO);
                }
            }
        }
    }

    /// The value at a point of the volume. Meaningful only when [`Field::is_volumetric`]; a
    /// UV-mapped image returns the midpoint of its range instead (exact when it is constant;
    /// check [`MediumField::is_volumetric`] or `Scene::require_volumetric` before rendering).
    #[inline]
    pub fn at_point(&self, p: DVec3) -> Rgb {
        match self {
            Field::Image(ImageField {
                mapping: ImageMapping::Uv,
                ..
            }) => (self.min() + self.max()) * 0.5,
            _ => self.eval(p, DVec2::ZERO),
        }
    }

    /// The uniform area average over the ellipse `e` as it lies in its plane (the
    /// flat-footprint reading of Eq. (3)), in constant time: the constant itself, or the
    /// pattern's closed form through the planar projection ([`het_estimate::prefilter`]), or a
    /// planar image's summed-area average ([`ImageField::ellipse_average`], whose table is
    /// built on the first call unless [`MediumField::build_area_tables`] built it). `None`
    /// for UV-mapped images (they need the texture coordinates over the plane:
    /// [`Field::ellipse_average_in_chart`]) and where a closed form or the table declines.
    pub fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Rgb> {
        match self {
            Field::Constant(v) => Some(*v),
            Field::Pattern {
                pattern,
                values,
                projection,
            } => {
                let f = pattern.fraction(&projection.footprint(e))?;
                Some(values[0] * (1.0 - f) + values[1] * f)
            }
            Field::Image(f) => f.ellipse_average(e),
        }
    }

    /// [`Field::ellipse_average`], with `chart` the texture coordinates over the ellipse's
    /// plane: UV-mapped images are averaged through it
    /// ([`ImageField::ellipse_average_in_chart`]), every other field as without it.
    pub fn ellipse_average_in_chart(&self, e: &PlanarEllipse, chart: &UvChart) -> Option<Rgb> {
        match self {
            Field::Image(f) if f.mapping == ImageMapping::Uv => {
                f.ellipse_average_in_chart(e, chart)
            }
            _ => self.ellipse_average(e),
        }
    }

    /// [`Field::eval_points`] at points of a plane whose texture coordinates `chart` gives (a
    /// UV-mapped image reads each point at `chart.uv_at(p)`).
    pub fn eval_points_in_chart(&self, ps: &[DVec3], chart: &UvChart, out: &mut [Rgb]) {
        match self {
            Field::Image(f) if f.mapping == ImageMapping::Uv => {
                for (p, o) in ps.iter().zip(out.iter_mut()) {
                    *o = f.at(*p, chart.uv_at(*p));
                }
            }
            _ => self.eval_points(ps, out),
        }
    }

    /// How displacements along the region's normal move this field's reading over the region
    /// `e` ([`CoefficientField::displacement_scale`]): L = max(s, h)/|sensitivity| (scene
    /// units), with the sensitivity the part of a unit normal displacement that moves the
    /// pattern's coordinate (|ĝ·n| for a stripe of direction ĝ; the sine of the normal's angle
    /// to the projection axis for checks and planar images, ĝ the normal's direction in the
    /// plane), s the feature size along ĝ (the width; for an image the distance across one
    /// texel along ĝ) and h the region's half extent along ĝ. `f64::INFINITY` where the
    /// reading does not move: constants, a normal along the projection axis, UV-mapped images
    /// (their chart reads points in the tangent plane).
    pub fn displacement_scale(&self, e: &PlanarEllipse) -> f64 {
        let n = e.normal;
        // Half extent of the region along the unit vector g.
        let half_extent =
            |g: DVec3| (g.dot(e.semi_major).powi(2) + g.dot(e.semi_minor).powi(2)).sqrt();
        let across = |axis: Axis| {
            let a = axis.unit();
            let pn = n - n.dot(a) * a;
            let sens = pn.length();
            (sens, if sens > 0.0 { pn / sens } else { DVec3::ZERO })
        };
        let scale = |feature: f64, sens: f64, g: DVec3| {
            if sens > 0.0 {
                feature.max(half_extent(g)) / sens
            } else {
                f64::INFINITY
            }
        };
        match self {
            _ if self.is_constant() => f64::INFINITY,
            Field::Constant(_) => f64::INFINITY,
            Field::Pattern {
                pattern: Pattern::Stripe(stripe),
                projection,
                ..
            } => {
                let (cos, sin) = stripe.direction();
                let g = projection.plane_vector(cos, sin);
                scale(stripe.width(), n.dot(g).abs(), g)
            }
            Field::Pattern {
                pattern: Pattern::Check(check),
                projection,
                ..
            } => {
                let (sens, g) = across(projection.axis);
                scale(check.width, sens, g)
            }
            Field::Image(f) => match f.mapping {
                ImageMapping::Uv => f64::INFINITY,
                ImageMapping::Planar { projection, size } => {
                    let (sens, g) = across(projection.axis);
                    // Texels crossed per unit length along g.
                    let (gs, gt) = projection.st_vector(g);
                    let per_length = ((gs * f.texture.width as f64 / size[0]).powi(2)
                        + (gt * f.texture.height as f64 / size[1]).powi(2))
                    .sqrt();
                    let texel = if per_length > 0.0 {
                        1.0 / per_length
                    } else {
                        f64::INFINITY
                    };
                    scale(texel, sens, g)
                }
            },
        }
    }

    /// False only for UV-mapped images (defined on the surface only).
    pub fn is_volumetric(&self) -> bool {
        !matches!(
            self,
            Field::Image(ImageField {
                mapping: ImageMapping::Uv,
                ..
            })
        )
    }

    /// True when every value has equal channels.
    pub fn is_grey(&self) -> bool {
        let grey = |v: Rgb| v[0] == v[1] && v[1] == v[2];
        match self {
            Field::Constant(v) => grey(*v),
            Field::Pattern { values, .. } => grey(values[0]) && grey(values[1]),
            Field::Image(f) => (grey(f.scale) && f.texture.is_grey()) || f.scale.is_zero(),
        }
    }

    /// Channel-wise smallest value over all points.
    pub fn min(&self) -> Rgb {
        match self {
            Field::Constant(v) => *v,
            Field::Pattern { values, .. } => values[0].zip_map(values[1], f64::min),
            Field::Image(f) => Rgb(f.texture.min().map(|c| c as f64)) * f.scale,
        }
    }

    /// Channel-wise largest value over all points (bilinear filtering interpolates convexly,
    /// so it never exceeds the largest texel).
    pub fn max(&self) -> Rgb {
        match self {
            Field::Constant(v) => *v,
            Field::Pattern { values, .. } => values[0].zip_map(values[1], f64::max),
            Field::Image(f) => Rgb(f.texture.max().map(|c| c as f64)) * f.scale,
        }
    }

    /// True when the field takes a single value.
    pub fn is_constant(&self) -> bool {
        self.min() == self.max()
    }

    /// The width of a varying pattern's bands or cells (scene units): the scale the medium
    /// changes on; `None` for constants and images.
    pub fn pattern_width(&self) -> Option<f64> {
        match self {
            _ if self.is_constant() => None,
            Field::Pattern {
                pattern: Pattern::Stripe(stripe),
                ..
            } => Some(stripe.width()),
            Field::Pattern {
                pattern: Pattern::Check(check),
                ..
            } => Some(check.width),
            _ => None,
        }
    }

    /// The directions a varying field defined in space changes along ([`Variation`]);
    /// `None` for a field that does not vary and for UV-mapped images (defined on the
    /// surface only).
    pub fn variation(&self) -> Option<Variation> {
        if self.is_constant() {
            return None;
        }
        match self {
            Field::Pattern {
                pattern: Pattern::Stripe(stripe),
                projection,
                ..
            } => {
                let (cos, sin) = stripe.direction();
                Some(Variation::Along(projection.plane_vector(cos, sin)))
            }
            Field::Pattern { projection, .. }
            | Field::Image(ImageField {
                mapping: ImageMapping::Planar { projection, .. },
                ..
            }) => Some(Variation::AcrossAxis(projection.axis)),
            _ => None,
        }
    }
}

/// The directions along which a field defined in space changes: every direction across its
/// projection axis (checks, planar images), or one direction of the pattern's plane (stripes).
/// Below a surface the field changes with depth where the surface's normal has a component
/// along them ([`Variation::depth_sine`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Variation {
    /// Constant along the axis, changing across it.
    AcrossAxis(Axis),
    /// Changing along this unit vector only.
    Along(DVec3),
}

impl Variation {
    /// The sine of the angle between the unit normal `n` and the directions the field is
    /// constant along: 0 where the field does not change with depth below a surface with
    /// normal `n`, 1 where depth is a direction it changes along.
    pub fn depth_sine(&self, n: DVec3) -> f64 {
        match *self {
            Variation::AcrossAxis(a) => (1.0 - n.dot(a.unit()).powi(2)).max(0.0).sqrt(),
            Variation::Along(g) => n.dot(g).abs(),
        }
    }

    /// For messages: `constant along x`, or `varying along (0.71, 0.71, 0.00) only` for a
    /// stripe.
    pub fn describe(&self) -> String {
        match *self {
            Variation::AcrossAxis(a) => format!("constant along {}", a.name()),
            Variation::Along(g) => {
                format!("varying along ({:.2}, {:.2}, {:.2}) only", g.x, g.y, g.z)
            }
        }
    }
}

/// The medium of a translucent material: σa and σs fields, or an artist's colour and mean
/// free path with the inversion that turns them into σa and σs ([`MediumField::artist`]), with
/// cached bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct MediumField {
    /// σa, or the artist's colour.
    sigma_a: Field,
    /// σs, or the artist's mean free path (scene units).
    sigma_s: Field,
    /// Present for an artist medium.
    artist: Option<ArtistMap>,
    /// Bounds of σa and σs.
    bounds: FieldBounds,
    /// Bounds of the two fields as given (`bounds` for a σ medium).
    raw_bounds: FieldBounds,
    majorant: Rgb,
    grey: bool,
    volumetric: bool,
    /// For a medium with a UV-mapped field, on one object: the texture coordinates inside
    /// its body ([`MediumField::with_interior`]).
    interior: Option<Arc<UvInterior>>,
}

/// The texture coordinates inside a body: those of the nearest point of its surface. What a
/// UV-mapped medium means below the surface for the path tracer, and what the estimators
/// already assume when they take the surface's coefficients to continue below it.
#[derive(Debug)]
pub struct UvInterior {
    tree: crate::geometry::closest::ClosestPointTree,
    /// Texture coordinates at each triangle's vertices (mesh order).
    uvs: Vec<[DVec2; 3]>,
}

/// Identity, not contents: two interiors are equal when they are the same one (a medium is
/// compared with its clones, which share it).
impl PartialEq for UvInterior {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

impl UvInterior {
    /// The interior of `mesh`; `None` for a mesh without texture coordinates or triangles.
    pub fn new(mesh: &crate::geometry::TriangleMesh) -> Option<Self> {
        let uvs = mesh.uvs.as_ref()?;
        if mesh.triangles.is_empty() {
            return None;
        }
        Some(Self {
            tree: crate::geometry::closest::ClosestPointTree::new(mesh),
            uvs: mesh
                .triangles
                .iter()
                .map(|t| t.map(|k| uvs[k as usize].as_dvec2()))
                .collect(),
        })
    }

    /// The texture coordinates of the surface point nearest to `p` (barycentric
    /// interpolation over its triangle, as a hit there reads them).
    #[inline]
    pub fn uv_at(&self, p: DVec3) -> Option<DVec2> {
        let n = self.tree.nearest(p)?;
        let t = self.uvs[n.prim as usize];
        let [b1, b2] = n.bary;
        Some((1.0 - b1 - b2) * t[0] + b1 * t[1] + b2 * t[2])
    }
}

impl MediumField {
    /// The medium with absorption `sigma_a` and scattering `sigma_s`.
    pub fn new(sigma_a: Field, sigma_s: Field) -> Self {
        let bounds = bounds_of(&sigma_a, &sigma_s);
        Self {
            majorant: bounds.max.sigma_a + bounds.max.sigma_s,
            grey: sigma_a.is_grey() && sigma_s.is_grey(),
            volumetric: sigma_a.is_volumetric() && sigma_s.is_volumetric(),
            interior: None,
            bounds,
            raw_bounds: bounds,
            artist: None,
            sigma_a,
            sigma_s,
        }
    }

    /// An artist's medium: `colour` (the diffuse colour of a thick flat slab, in [0, 1]) and
    /// `mfp` (mean free path, scene units, > 0 somewhere; σt = 1/mfp), turned into σa and σs
    /// by `map` at each point (see [`ArtistMap`] for the floor on zero mean free paths and
    /// [`InvertAt`] for where estimators invert). Errors: a colour above 1, or a mean free
    /// path that is 0 everywhere (the loader turns that into a diffuse surface instead).
    pub fn artist(colour: Field, mfp: Field, map: ArtistMap) -> Result<Self, FieldError> {
        if colour.max().max_component() > 1.0 {
            return Err(FieldError::BadValue {
                what: "subsurface_color (at most 1)".into(),
                value: colour.max().0,
            });
        }
        let raw_bounds = bounds_of(&colour, &mfp);
        let map = map.with_floor(mfp.max())?;
        let bounds = map.bounds(&raw_bounds);
        Ok(Self {
            majorant: bounds.max.sigma_a + bounds.max.sigma_s,
            grey: colour.is_grey() && mfp.is_grey(),
            volumetric: colour.is_volumetric() && mfp.is_volumetric(),
            interior: None,
            bounds,
            raw_bounds,
            artist: Some(map),
            sigma_a: colour,
            sigma_s: mfp,
        })
    }

    /// A homogeneous medium.
    pub fn homogeneous(c: Coefficients) -> Result<Self, FieldError> {
        Ok(Self::new(
            Field::constant(c.sigma_a)?,
            Field::constant(c.sigma_s)?,
        ))
    }

    /// The absorption field (for an artist medium: the colour field).
    pub fn sigma_a(&self) -> &Field {
        &self.sigma_a
    }
    /// The scattering field (for an artist medium: the mean free path field).
    pub fn sigma_s(&self) -> &Field {
        &self.sigma_s
    }
    /// The two fields with their scene-file names (`sigma_a`, `sigma_s`, or
    /// `subsurface_color`, `subsurface_radius`), for messages.
    pub fn named_fields(&self) -> [(&'static str, &Field); 2] {
        match self.artist {
            None => [("sigma_a", &self.sigma_a), ("sigma_s", &self.sigma_s)],
            Some(_) => [
                ("subsurface_color", &self.sigma_a),
                ("subsurface_radius", &self.sigma_s),
            ],
        }
    }
    /// The artist parametrisation, if this medium has one.
    pub fn artist_map(&self) -> Option<&ArtistMap> {
        self.artist.as_ref()
    }

    /// The same medium with the estimators inverting an artist's parameters at `invert` (a
    /// σ medium is returned unchanged).
    pub fn with_invert(mut self, invert: InvertAt) -> Self {
        if let Some(map) = self.artist.take() {
            self.artist = Some(map.with_invert(invert));
        }
        self
    }

    /// The medium multiplied by `k` (unit conversion: coefficients per file unit ×
    /// `unit_scale` = per scene unit; an artist's mean free path is divided by `k`).
    pub fn scaled(self, k: f64) -> Self {
        match self.artist {
            None => Self::new(self.sigma_a.scaled(k), self.sigma_s.scaled(k)),
            Some(map) => {
                let colour = self.sigma_a;
                let mfp = self.sigma_s.scaled(1.0 / k);
                // Valid before, so valid scaled (k > 0 is checked by the loader).
                Self::artist(colour, mfp, map.without_floor())
                    .expect("a valid artist medium stays valid when scaled")
            }
        }
    }

    /// σa and σs of the two fields' values: the values themselves for a σ medium (one
    /// predictable branch; the artist path is kept out of line so that it does not weigh on
    /// the σ path's inlining).
    #[inline]
    fn to_sigma(&self, raw: Coefficients) -> Coefficients {
        match &self.artist {
            None => raw,
            Some(map) => map.coefficients_out_of_line(raw),
        }
    }

    /// Coefficients at a point of the volume (for the path tracer): cheap, no allocation (an
    /// artist medium costs three table lookups more). Meaningful when
    /// [`MediumField::is_volumetric`], or, for a medium with UV-mapped fields, once
    /// [`MediumField::with_interior`] gave it its body: those fields are then read at the
    /// texture coordinates of the nearest surface point (a closest-point search, ≈ a ray's
    /// cost).
    #[inline]
    pub fn at_point(&self, p: DVec3) -> Coefficients {
        if !self.volumetric
            && let Some(uv) = self.interior.as_ref().and_then(|i| i.uv_at(p))
        {
            return self.at_surface(p, uv);
        }
        self.to_sigma(Coefficients {
            sigma_a: self.sigma_a.at_point(p),
            sigma_s: self.sigma_s.at_point(p),
        })
    }

    /// The same medium filling the body of `mesh`: a UV-mapped field is read inside it at the
    /// texture coordinates of the nearest surface point ([`UvInterior`]), so that the path
    /// tracer can walk it. Unchanged for a medium defined in space, or where the mesh has no
    /// texture coordinates.
    pub fn with_interior(mut self, mesh: &crate::geometry::TriangleMesh) -> Self {
        if !self.volumetric {
            self.interior = UvInterior::new(mesh).map(Arc::new);
        }
        self
    }

    /// True when the path tracer can read the medium inside a body: defined in space, or
    /// given its body ([`MediumField::with_interior`]).
    pub fn is_path_traceable(&self) -> bool {
        self.volumetric || self.interior.is_some()
    }

    /// Coefficients at a surface point with texture coordinates `uv`.
    #[inline]
    pub fn at_surface(&self, p: DVec3, uv: DVec2) -> Coefficients {
        self.to_sigma(self.raw_at_surface(p, uv))
    }

    #[inline]
    fn raw_at_surface(&self, p: DVec3, uv: DVec2) -> Coefficients {
        Coefficients {
            sigma_a: self.sigma_a.eval(p, uv),
            sigma_s: self.sigma_s.eval(p, uv),
        }
    }

    /// The raw values at a point in the estimators' averaging space: σa and σs (an artist's
    /// colour and mean free path inverted here), unless they average the colour and mean
    /// free path themselves ([`InvertAt::After`]).
    #[inline]
    fn in_averaging_space(&self, raw: Coefficients) -> Coefficients {
        match &self.artist {
            None => raw,
            Some(map) if map.invert() == InvertAt::After => raw,
            Some(map) => map.coefficients_out_of_line(raw),
        }
    }

    /// True when the estimators average an artist's colour and mean free path and invert the
    /// means ([`InvertAt::After`]).
    #[inline]
    fn inverts_after(&self) -> bool {
        matches!(&self.artist, Some(m) if m.invert() == InvertAt::After)
    }

    /// False when either field is a UV-mapped image (surface only).
    pub fn is_volumetric(&self) -> bool {
        self.volumetric
    }

    /// True when every value of both fields has equal channels (one channel can be traced
    /// for all three).
    pub fn is_grey(&self) -> bool {
        self.grey
    }

    /// True when neither field varies.
    pub fn is_constant(&self) -> bool {
        self.bounds.is_constant()
    }

    /// The narrowest pattern width of σa and σs ([`Field::pattern_width`]).
    pub fn pattern_width(&self) -> Option<f64> {
        match (self.sigma_a.pattern_width(), self.sigma_s.pattern_width()) {
            (Some(a), Some(s)) => Some(a.min(s)),
            (a, s) => a.or(s),
        }
    }

    /// Per-channel majorant of σt = σa + σs over the whole medium (for an artist medium,
    /// 1 / the smallest mean free path after its floor).
    pub fn majorant(&self) -> Rgb {
        self.majorant
    }

    /// Builds the summed-area tables of the image fields whose region averages an estimator
    /// may ask for (every image, unless the medium is an artist medium inverted before
    /// averaging, which has no region averages). Each texture's table is built once and shared
    /// (`Texture::area_table`); a render calls this while it is prepared, so that no sample
    /// waits for a table.
    pub fn build_area_tables(&self) {
        if !CoefficientField::<Hit>::capabilities(self).ellipse_average {
            return;
        }
        for field in [&self.sigma_a, &self.sigma_s] {
            if let Field::Image(f) = field {
                f.texture.area_table();
            }
        }
    }

    /// The textures whose summed-area tables [`MediumField::build_area_tables`] would build
    /// (none already built), for a memory estimate before a render is prepared.
    pub fn area_table_textures(&self) -> Vec<&Arc<Texture>> {
        if !CoefficientField::<Hit>::capabilities(self).ellipse_average {
            return Vec::new();
        }
        [&self.sigma_a, &self.sigma_s]
            .into_iter()
            .filter_map(|field| match field {
                Field::Image(f) if !f.texture.has_area_table() => Some(&f.texture),
                _ => None,
            })
            .collect()
    }

    /// Channel-wise bounds of both coefficients (σa and σs, for every parametrisation).
    pub fn field_bounds(&self) -> FieldBounds {
        self.bounds
    }

    /// Both fields' region averages by `average`, in the averaging space; `None` if either
    /// declines, and always for an artist medium inverted before averaging (the mean of a
    /// nonlinear function of the textures has no summed-area table).
    #[inline]
    fn both_averages(&self, average: impl Fn(&Field) -> Option<Rgb>) -> Option<Coefficients> {
        if self.artist.is_some() && !self.inverts_after() {
            return None;
        }
        Some(Coefficients {
            sigma_a: average(&self.sigma_a)?,
            sigma_s: average(&self.sigma_s)?,
        })
    }

    /// Both fields at every point of `xs` by `eval` (a chunk at a time), into `out`, in the
    /// averaging space.
    #[inline]
    fn read_points(
        &self,
        xs: &[DVec3],
        out: &mut [Coefficients],
        eval: impl Fn(&Field, &[DVec3], &mut [Rgb]),
    ) {
        let mut buf = [Rgb::ZERO; het_estimate::CHUNK];
        for (xs, out) in xs.chunks(buf.len()).zip(out.chunks_mut(buf.len())) {
            let b = &mut buf[..xs.len()];
            eval(&self.sigma_a, xs, b);
            for (o, v) in out.iter_mut().zip(b.iter()) {
                o.sigma_a = *v;
            }
            eval(&self.sigma_s, xs, b);
            for (o, v) in out.iter_mut().zip(b.iter()) {
                o.sigma_s = *v;
            }
        }
        if self.artist.is_some() {
            out.iter_mut()
                .for_each(|c| *c = self.in_averaging_space(*c));
        }
    }
}

/// Channel-wise bounds of two fields.
fn bounds_of(a: &Field, s: &Field) -> FieldBounds {
    let min = Coefficients {
        sigma_a: a.min(),
        sigma_s: s.min(),
    };
    let max = Coefficients {
        sigma_a: a.max(),
        sigma_s: s.max(),
    };
    if min == max {
        FieldBounds::constant(min)
    } else {
        FieldBounds { min, max }
    }
}

impl CoefficientField<Hit> for MediumField {
    #[inline]
    fn coefficients(&self, p: &Hit) -> Coefficients {
        self.at_surface(p.p, p.uv)
    }

    /// Always `Some`; `FieldBounds::constant` for a homogeneous medium. In the averaging space
    /// ([`CoefficientField::averaged`]): the colour and mean free path for an artist medium
    /// inverted after averaging.
    fn bounds(&self) -> Option<FieldBounds> {
        Some(if self.inverts_after() {
            self.raw_bounds
        } else {
            self.bounds
        })
    }

    /// Both fields' [`Field::ellipse_average`]; `None` if either declines, and always for an
    /// artist medium inverted before averaging (the mean of a nonlinear function of the
    /// textures has no summed-area table).
    fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Coefficients> {
        self.both_averages(|f| f.ellipse_average(e))
    }

    /// Constant-time region averages unless the medium is an artist medium inverted before
    /// averaging (every field has one for some regions: UV-mapped images through a chart,
    /// [`CoefficientField::ellipse_average_in_chart`]); texture coordinates when either field
    /// is a UV-mapped image; point lookups in space otherwise; the colour and mean free path
    /// as averaging space for an artist medium inverted after averaging.
    #[inline]
    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities {
            ellipse_average: self.artist.is_none() || self.inverts_after(),
            reads_uv: !self.volumetric,
            point_lookup: self.is_volumetric(),
            own_averaging_space: self.inverts_after(),
        }
    }

    /// The smaller of the two fields' [`Field::displacement_scale`] (an artist medium's colour
    /// and mean free path fields, whichever space it averages in).
    fn displacement_scale(&self, e: &PlanarEllipse) -> Option<f64> {
        Some(
            self.sigma_a
                .displacement_scale(e)
                .min(self.sigma_s.displacement_scale(e)),
        )
    }

    /// Both fields' [`Field::ellipse_average_in_chart`]; `None` as for
    /// [`CoefficientField::ellipse_average`].
    fn ellipse_average_in_chart(&self, e: &PlanarEllipse, chart: &UvChart) -> Option<Coefficients> {
        self.both_averages(|f| f.ellipse_average_in_chart(e, chart))
    }

    /// Each field at every point, UV-mapped images at the coordinates `chart` gives
    /// ([`Field::eval_points_in_chart`]): what surface hits at those points would read.
    fn averaged_at_points_in_chart(
        &self,
        xs: &[DVec3],
        chart: &UvChart,
        out: &mut [Coefficients],
    ) -> bool {
        self.read_points(xs, out, |f, xs, b| f.eval_points_in_chart(xs, chart, b));
        true
    }

    /// The colour and mean free path for an artist medium inverted after averaging; σa and σs
    /// otherwise.
    #[inline]
    fn averaged(&self, p: &Hit) -> Coefficients {
        self.in_averaging_space(self.raw_at_surface(p.p, p.uv))
    }

    /// [`CoefficientField::averaged`] at a point of space, for media that do not read texture
    /// coordinates (every field but UV-mapped images): the same value a surface hit at `x`
    /// would give.
    #[inline]
    fn averaged_at_point(&self, x: DVec3) -> Option<Coefficients> {
        if !self.is_volumetric() {
            return None;
        }
        Some(self.in_averaging_space(self.raw_at_surface(x, DVec2::ZERO)))
    }

    /// Each field decides what it is once for all the points ([`Field::eval_points`]).
    fn averaged_at_points(&self, xs: &[DVec3], out: &mut [Coefficients]) -> bool {
        if !self.is_volumetric() {
            return false;
        }
        self.read_points(xs, out, |f, xs, b| f.eval_points(xs, b));
        true
    }

    #[inline]
    fn coefficients_of_mean(&self, mean: Coefficients) -> Coefficients {
        if self.inverts_after() {
            self.to_sigma(mean)
        } else {
            mean
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reading many points together gives, bit for bit, what reading each gives: every kind
    /// of field (constant, stripe, check, planar image, an artist's medium inverted before or
    /// after averaging), and more points than one chunk.
    #[test]
    fn points_read_together_equal_points_read_alone() {
        use crate::field::artist::{ArtistMap, InvertAt};
        use bssrdf_core::{AlbedoInversion, ProfileModel};
        let proj = PlanarProjection::new(Axis::Z, DVec3::new(0.2, -0.3, 0.0));
        let lo_hi = [Rgb::new(0.01, 0.02, 0.03), Rgb::new(0.1, 0.2, 0.3)];
        let texels = (0..16 * 16)
            .map(|k| {
                [
                    0.1 + 0.05 * (k % 7) as f32,
                    0.2,
                    0.3 + 0.01 * (k % 5) as f32,
                ]
            })
            .collect();
        let tex = Arc::new(Texture::from_texels("t", 16, 16, texels).unwrap());
        let image = Field::image(
            tex,
            ImageMapping::Planar {
                projection: proj,
                size: [7.0, 5.0],
            },
            Wrap::Repeat,
            Filter::Bilinear,
            Rgb::ONE,
        )
        .unwrap();
        let fields = [
            Field::constant(Rgb::new(0.5, 1.0, 2.0)).unwrap(),
            Field::stripe(1.5, 0.4, lo_hi, proj).unwrap(),
            Field::check(2.0, lo_hi, proj).unwrap(),
            image,
        ];
        let inversion = Arc::new(AlbedoInversion::new(ProfileModel::Dipole, 0.0, 1.3).unwrap());
        let mut media: Vec<MediumField> = fields
            .iter()
            .flat_map(|a| {
                fields
                    .iter()
                    .map(|s| MediumField::new(a.clone(), s.clone()))
            })
            .collect();
        for invert in [InvertAt::Before, InvertAt::After] {
            let colour = Field::check(2.0, [Rgb::splat(0.3), Rgb::splat(0.8)], proj).unwrap();
            let mfp = Field::stripe(1.5, 0.4, [Rgb::splat(0.5), Rgb::splat(2.0)], proj).unwrap();
            let map = ArtistMap::new(inversion.clone(), invert);
            media.push(MediumField::artist(colour, mfp, map).unwrap());
        }
        let xs: Vec<DVec3> = (0..77)
            .map(|k| {
                let t = k as f64;
                DVec3::new(
                    9.0 * (0.37 * t).sin(),
                    7.0 * (0.71 * t).cos(),
                    (1.3 * t).sin(),
                )
            })
            .collect();
        for (m, medium) in media.iter().enumerate() {
            let mut out = vec![Coefficients::default(); xs.len()];
            assert!(CoefficientField::<Hit>::averaged_at_points(
                medium, &xs, &mut out
            ));
            for (k, x) in xs.iter().enumerate() {
                let one = CoefficientField::<Hit>::averaged_at_point(medium, *x).unwrap();
                assert_eq!(out[k], one, "medium {m}, point {k}");
            }
        }
        for (f, field) in fields.iter().enumerate() {
            let mut out = vec![Rgb::ZERO; xs.len()];
            field.eval_points(&xs, &mut out);
            for (k, x) in xs.iter().enumerate() {
                assert_eq!(out[k], field.eval(*x, DVec2::ZERO), "field {f}, point {k}");
            }
        }
    }

    #[test]
    fn stripe_and_check_read_the_shared_patterns() {
        let a = Rgb::splat(0.1);
        let b = Rgb::new(1.0, 2.0, 3.0);
        let proj = PlanarProjection::new(Axis::Z, DVec3::new(0.5, -0.25, 7.0));
        let stripe = Stripe::new(1.5, 0.3);
        let fs = Field::stripe(1.5, 0.3, [a, b], proj).unwrap();
        let fc = Field::check(0.7, [a, b], proj).unwrap();
        let check = Check { width: 0.7 };
        for i in 0..400 {
            let p = DVec3::new(
                (i as f64 * 0.731).sin() * 5.0,
                (i as f64 * 1.37).cos() * 5.0,
                i as f64 * 0.01,
            );
            let (s, t) = (p.x - 0.5, p.y + 0.25);
            assert_eq!(fs.at_point(p), [a, b][stripe.select(s, t)]);
            assert_eq!(fc.at_point(p), [a, b][check.select(s, t)]);
        }
        let m = MediumField::new(fs, Field::constant(Rgb::ONE).unwrap());
        assert!(!m.is_grey() && m.is_volumetric() && !m.is_constant());
        assert_eq!(m.majorant(), Rgb::new(2.0, 3.0, 4.0));
    }

    /// The closed-form ellipse average of a projected pattern against the mean over 40,000
    /// uniform points of the same ellipse (tilted to the projection axis, fixed seed), at 5
    /// standard errors of the Bernoulli mean; image fields decline (they are sampled).
    #[test]
    fn pattern_ellipse_average_matches_monte_carlo() {
        let (a, b) = (Rgb::new(0.1, 0.2, 0.3), Rgb::new(1.0, 2.0, 4.0));
        let proj = PlanarProjection::new(Axis::X, DVec3::new(0.0, 0.5, -0.25));
        let normal = DVec3::new(0.8, 0.36, 0.48);
        let major = normal.any_orthonormal_vector();
        let minor = normal.cross(major);
        let e = PlanarEllipse {
            centre: DVec3::new(3.0, 1.0, -2.0),
            semi_major: 5.0 * major,
            semi_minor: 2.0 * minor,
            normal,
        };
        for field in [
            Field::stripe(1.5, 0.3, [a, b], proj).unwrap(),
            Field::check(1.2, [a, b], proj).unwrap(),
        ] {
            let exact = field.ellipse_average(&e).unwrap();
            let f = (exact[0] - a[0]) / (b[0] - a[0]);
            let mut rng = crate::rng::Rng::from_keys(77, &[]);
            let n = 40_000;
            let mut ones = 0usize;
            for _ in 0..n {
                let u = loop {
                    let u = DVec2::new(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
                    if u.length_squared() <= 1.0 {
                        break u;
                    }
                };
                let v = field.at_point(e.centre + u.x * e.semi_major + u.y * e.semi_minor);
                ones += (v == b) as usize;
            }
            let mc = ones as f64 / n as f64;
            let se = (mc * (1.0 - mc) / n as f64).sqrt();
            assert!(mc > 0.05 && mc < 0.95, "a footprint over both values: {mc}");
            assert!((f - mc).abs() <= 5.0 * se, "{f} vs {mc} ± {se}");
            // Every channel gets the same fraction.
            assert!(((exact[2] - a[2]) / (b[2] - a[2]) - f).abs() < 1e-12);
        }
        let tex = Arc::new(Texture::from_texels("t", 1, 1, vec![[1.0; 3]]).unwrap());
        let img = Field::image(
            tex,
            ImageMapping::Uv,
            Wrap::Clamp,
            Filter::Nearest,
            Rgb::ONE,
        );
        assert!(img.unwrap().ellipse_average(&e).is_none());
    }

    /// The summed-area average of a planar image (16×12 random texels, RGB) over an ellipse
    /// tilted to the projection axis and spanning the image edge, against the mean of 100,000
    /// uniform points of the ellipse (fixed seed), per channel: within 5 standard errors for
    /// nearest filtering, and within 5 standard errors plus the documented box-for-bilinear
    /// bound `(max − min)·P/(8|R|)` for bilinear, for both wrap modes. The ellipse is large
    /// (about 9 × 4 texels) and then small enough (under 16 rows) to use level 0.
    #[test]
    fn image_ellipse_average_matches_monte_carlo() {
        let (w, h) = (16u32, 12u32);
        let mut rng = crate::rng::Rng::from_keys(11, &[]);
        let texels = (0..w * h)
            .map(|_| {
                let v = rng.uniform() as f32;
                [v, v * v, 1.0 - v]
            })
            .collect();
        let tex = Arc::new(Texture::from_texels("r", w, h, texels).unwrap());
        let proj = PlanarProjection::new(Axis::Z, DVec3::new(0.3, -0.2, 0.0));
        let size = [4.0, 3.0]; // 0.25 scene units per texel
        let normal = DVec3::new(0.1, -0.2, 1.0).normalize();
        let major = normal.cross(DVec3::new(1.0, 0.4, 0.0)).normalize();
        let minor = normal.cross(major);
        for (semi_major, semi_minor, centre) in [
            (2.3, 1.0, DVec3::new(1.5, 0.9, 0.0)),
            (0.6, 0.35, DVec3::new(-1.8, -1.1, 0.0)),
        ] {
            let e = PlanarEllipse {
                centre,
                semi_major: semi_major * major,
                semi_minor: semi_minor * minor,
                normal,
            };
            for wrap in [Wrap::Repeat, Wrap::Clamp] {
                for filter in [Filter::Nearest, Filter::Bilinear] {
                    let field = Field::image(
                        tex.clone(),
                        ImageMapping::Planar {
                            projection: proj,
                            size,
                        },
                        wrap,
                        filter,
                        Rgb::new(1.0, 2.0, 0.5),
                    )
                    .unwrap();
                    let got = field.ellipse_average(&e).unwrap();
                    let mut rng = crate::rng::Rng::from_keys(77, &[]);
                    let n = 100_000;
                    let (mut sum, mut sq) = (Rgb::ZERO, Rgb::ZERO);
                    for _ in 0..n {
                        let u = loop {
                            let u =
                                DVec2::new(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
                            if u.length_squared() <= 1.0 {
                                break u;
                            }
                        };
                        let v = field.at_point(e.centre + u.x * e.semi_major + u.y * e.semi_minor);
                        sum += v;
                        sq += v * v;
                    }
                    let mean = sum * (1.0 / n as f64);
                    let (lo, hi) = (field.min(), field.max());
                    // Footprint in texels (4 texels per unit): perimeter / area of the
                    // projected ellipse, by Ramanujan's perimeter on the in-plane ellipse
                    // scaled by the projection (n·z ≈ 0.91): an over-estimate is harmless.
                    let (a, b) = (semi_major * 4.0, semi_minor * 4.0 * normal.z);
                    let perimeter = std::f64::consts::PI
                        * (3.0 * (a + b) - ((3.0 * a + b) * (a + 3.0 * b)).sqrt());
                    let bilinear_bound = perimeter / (8.0 * std::f64::consts::PI * a * b);
                    for c in 0..3 {
                        let var = sq[c] / n as f64 - mean[c] * mean[c];
                        let se = (var / n as f64).sqrt();
                        let bias = match filter {
                            Filter::Nearest => 0.0,
                            Filter::Bilinear => (hi[c] - lo[c]) * bilinear_bound,
                        };
                        assert!(
                            (got[c] - mean[c]).abs() <= 5.0 * se + bias,
                            "{wrap:?} {filter:?} c{c} ({semi_major}): {} vs {} ± {se} (+{bias})",
                            got[c],
                            mean[c]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn constant_medium_bounds_are_constant() {
        let m = MediumField::homogeneous(Coefficients::grey(0.1, 2.0)).unwrap();
        let b = CoefficientField::<Hit>::bounds(&m).unwrap();
        assert!(b.is_constant() && m.is_grey());
        assert!(Field::constant(Rgb::new(0.0, -1.0, 0.0)).is_err());
        assert!(Field::check(0.0, [Rgb::ONE; 2], PlanarProjection::default()).is_err());
    }

    #[test]
    fn planar_image_placement() {
        // 2x2 image of width/height 4 centred at the origin: texel (0,0) (top-left) covers
        // s ∈ [−2, 0], t ∈ [0, 2].
        let tex = Arc::new(
            Texture::from_texels("t", 2, 2, vec![[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]]).unwrap(),
        );
        let f = Field::image(
            tex.clone(),
            ImageMapping::Planar {
                projection: PlanarProjection::default(),
                size: [4.0, 4.0],
            },
            Wrap::Clamp,
            Filter::Nearest,
            Rgb::splat(2.0),
        )
        .unwrap();
        assert_eq!(f.at_point(DVec3::new(-1.0, 1.0, 9.0)), Rgb::splat(0.0));
        assert_eq!(f.at_point(DVec3::new(1.0, 1.0, 9.0)), Rgb::splat(2.0));
        assert_eq!(f.at_point(DVec3::new(-1.0, -1.0, 9.0)), Rgb::splat(4.0));
        assert_eq!(f.max(), Rgb::splat(6.0));
        let uvf = Field::image(
            tex,
            ImageMapping::Uv,
            Wrap::Clamp,
            Filter::Nearest,
            Rgb::ONE,
        )
        .unwrap();
        assert!(!uvf.is_volumetric());
        // uv (0.25, 0.75): v up, so the top row: texel (0, 0).
        assert_eq!(
            uvf.eval(DVec3::ZERO, DVec2::new(0.25, 0.75)),
            Rgb::splat(0.0)
        );
        assert_eq!(
            uvf.eval(DVec3::ZERO, DVec2::new(0.75, 0.25)),
            Rgb::splat(3.0)
        );
    }
}
