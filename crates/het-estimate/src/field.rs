//! The coefficient-lookup trait and the per-channel coefficient pair.

use crate::ellipse::PlanarEllipse;
use crate::uv_chart::UvChart;

/// Absorption and scattering coefficients per colour channel, in 1/length (defined in
/// `bssrdf-core`, where the profiles take them).
pub use bssrdf_core::Coefficients;

/// Channel-wise bounds of a field over the whole object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldBounds {
    /// Smallest value of each coefficient and channel.
    pub min: Coefficients,
    /// Largest value of each coefficient and channel.
    pub max: Coefficients,
}

impl FieldBounds {
    /// Bounds of a constant field.
    pub const fn constant(c: Coefficients) -> Self {
        Self { min: c, max: c }
    }
    /// True when the field cannot vary (min == max): averaging it is pointless.
    #[inline]
    pub fn is_constant(&self) -> bool {
        self.min == self.max
    }
}

/// The optional capabilities of a [`CoefficientField`], as one value
/// ([`CoefficientField::capabilities`]). Each flag says that the field answers the methods it
/// names; the estimators ask those only then. All false by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FieldCapabilities {
    /// [`CoefficientField::ellipse_average`] (or, for a field that reads texture coordinates,
    /// [`CoefficientField::ellipse_average_in_chart`]) can answer, for some regions. The
    /// estimator asks for field averages, checks the surface's flatness and counts fallbacks
    /// only for such fields.
    pub ellipse_average: bool,
    /// The field reads the surface's texture coordinates (a UV-mapped image), so that its
    /// constant-time averages need the texture coordinates over the region: the estimators
    /// then ask [`CoefficientField::ellipse_average_in_chart`] and
    /// [`CoefficientField::averaged_at_points_in_chart`] instead of the chart-free versions,
    /// with the region's chart from [`crate::SurfaceQuery::uv_chart`] at x_i and x_o
    /// ([`UvChart::between`]), and sample the region where there is none.
    pub reads_uv: bool,
    /// [`CoefficientField::averaged_at_point`] can answer.
    pub point_lookup: bool,
    /// [`CoefficientField::averaged`] is not σa, σs but values of the field's own averaging
    /// space. Estimators then map means through [`CoefficientField::coefficients_of_mean`]
    /// (which they skip, at no cost, when this is false: override the three together) and
    /// take plain arithmetic means (the kernel estimator's power mean of σa is specific to
    /// σa).
    pub own_averaging_space: bool,
}

/// σa and σs over the surface of the object being shaded.
pub trait CoefficientField<P> {
    /// The coefficients at surface point `p`. Must be finite and non-negative.
    fn coefficients(&self, p: &P) -> Coefficients;

    /// Bounds over the whole object, if known. A constant field returns
    /// `Some(FieldBounds::constant(c))`, which lets every estimator skip averaging so that a
    /// homogeneous material costs no more than a point lookup. The default, `None`, means
    /// "unknown: average".
    ///
    /// Report bounds whenever you know them: they also make constants come back *exactly*.
    /// Without bounds, `segment` and `sone` average a constant field by summing weighted
    /// samples, which returns the constant only to rounding (up to about 1e-15 relative), and
    /// estimates are clamped to the bounds when they are known.
    fn bounds(&self) -> Option<FieldBounds> {
        None
    }

    /// What the field can do beyond point lookups (constant-time region averages, texture
    /// coordinates, point lookups in space, its own averaging space): see
    /// [`FieldCapabilities`]. Default: none of them. Override it together with the methods
    /// the capabilities name.
    #[inline]
    fn capabilities(&self) -> FieldCapabilities {
        FieldCapabilities::default()
    }

    /// Optional capability: the exact (or prefiltered) area average of Eq. (3) of the paper
    /// over `region`, i.e. the mean of the coefficients at the projections of the ellipse's
    /// points onto the surface along `±region.normal`, uniformly weighted by area in the
    /// ellipse's plane. Fields that can answer in constant time (summed-area tables, EWA over
    /// a texture, closed forms: see [`crate::prefilter`]) override this together with
    /// [`FieldCapabilities::ellipse_average`]; the Sone estimator then asks it before
    /// sampling wherever the surface is flat enough for a flat footprint (see
    /// `SoneParams::averaging` and [`crate::Flatness`]). An implementation may answer for the
    /// ellipse as it lies in its plane (the flat-surface reading). `None` means "not for this
    /// region: sample it"; the default always returns `None` and costs nothing.
    fn ellipse_average(&self, region: &PlanarEllipse) -> Option<Coefficients> {
        let _ = region;
        None
    }

    /// Optional capability for curved surfaces: the length L (scene units) that scales how
    /// the field's reading over `region` moves when the surface departs from the region's
    /// plane: displacing every point by at most δ along `region.normal` moves the region's
    /// average by about (2/π)·δ/L of the field's contrast at most
    /// (`docs/physics.md#prefiltered-averages`, "Curved surfaces"). With ĝ the unit direction
    /// in which a displacement along the normal moves the field's own coordinates, s the
    /// field's feature size along ĝ (a stripe's or a check's width, a texel) and h the
    /// region's half extent along ĝ in those coordinates, L = max(s, h)/|sensitivity|
    /// (|sensitivity| the fraction of a normal displacement that moves the coordinates:
    /// |ĝ·n| for a stripe, the sine of the normal's angle to a planar projection's axis). A
    /// field that does not change along the normal (a constant, a planar projection seen
    /// along its axis, texture coordinates, which a chart reads in the tangent plane) returns
    /// `f64::INFINITY`. `None` (the default): unknown; the estimators then prefilter only
    /// pairs that are flat by [`crate::Flatness`]'s angle test, and project the rest.
    fn displacement_scale(&self, region: &PlanarEllipse) -> Option<f64> {
        let _ = region;
        None
    }

    /// [`CoefficientField::ellipse_average`] for a field that
    /// [reads texture coordinates](FieldCapabilities::reads_uv): `chart` maps the region's
    /// plane to them (the region lies in the surface: a flat pair). A UV-mapped image averages
    /// over the footprint the chart gives (the ellipse's axes mapped by the chart's gradients:
    /// the UV Jacobian at the region's centre). The default ignores the chart.
    fn ellipse_average_in_chart(
        &self,
        region: &PlanarEllipse,
        chart: &UvChart,
    ) -> Option<Coefficients> {
        let _ = chart;
        self.ellipse_average(region)
    }

    /// [`CoefficientField::averaged_at_points`] for a field that
    /// [reads texture coordinates](FieldCapabilities::reads_uv): each point of the region's
    /// plane is read at the coordinates `chart` gives it. The default ignores the chart.
    #[inline]
    fn averaged_at_points_in_chart(
        &self,
        xs: &[glam::DVec3],
        chart: &UvChart,
        out: &mut [Coefficients],
    ) -> bool {
        let _ = chart;
        self.averaged_at_points(xs, out)
    }

    /// Optional capability: [`CoefficientField::averaged`] at a point `x` of space, for a field
    /// that is a function of position alone (a planar projection, a procedural field: no
    /// texture coordinates, so no surface query is needed). The `kernel` estimator reads it at
    /// the points of its averaging plane instead of projecting each onto the surface, where
    /// the pair is flat enough that the plane is the surface (`KernelParams::averaging`,
    /// [`crate::Flatness`]): the same values without two rays per point. `None` means "project
    /// this point"; the default always returns `None`. Values as for `averaged`.
    fn averaged_at_point(&self, x: glam::DVec3) -> Option<Coefficients> {
        let _ = x;
        None
    }

    /// [`CoefficientField::averaged_at_point`] at every point of `xs`, into `out` (as long as
    /// `xs`): the estimators hand over a chunk of projected points together, so that a field
    /// can decide what it is once per chunk. `false` (with `out` unspecified) where the field
    /// has no point lookup. The default asks `averaged_at_point` for each.
    #[inline]
    fn averaged_at_points(&self, xs: &[glam::DVec3], out: &mut [Coefficients]) -> bool {
        for (x, o) in xs.iter().zip(out.iter_mut()) {
            match self.averaged_at_point(*x) {
                Some(c) => *o = c,
                None => return false,
            }
        }
        true
    }

    /// Optional averaging space: the values the estimators average at `p`, in the two slots
    /// of a [`Coefficients`]. The default is [`CoefficientField::coefficients`] itself (σa and
    /// σs are averaged). A field whose coefficients are a nonlinear function of other
    /// quantities may average those instead (e.g. an artist's colour and mean free path,
    /// inverted to σa, σs only after averaging: `docs/artist-parameters.md`); it then
    /// overrides [`CoefficientField::coefficients_of_mean`] to map a mean back to coefficients, and
    /// returns [`CoefficientField::bounds`] and [`CoefficientField::ellipse_average`] in the
    /// averaging space too. Values must be finite and non-negative.
    #[inline]
    fn averaged(&self, p: &P) -> Coefficients {
        self.coefficients(p)
    }

    /// The coefficients of a mean of [`CoefficientField::averaged`] values (default: the
    /// mean itself). Every estimator maps each mean it uses (the widths of Sone's ellipse, the
    /// kernel's weights, the final estimate) through this. Must return finite, non-negative
    /// coefficients for finite, non-negative input.
    #[inline]
    fn coefficients_of_mean(&self, mean: Coefficients) -> Coefficients {
        mean
    }
}

impl<P, F: CoefficientField<P> + ?Sized> CoefficientField<P> for &F {
    fn coefficients(&self, p: &P) -> Coefficients {
        (**self).coefficients(p)
    }
    #[inline]
    fn capabilities(&self) -> FieldCapabilities {
        (**self).capabilities()
    }
    fn bounds(&self) -> Option<FieldBounds> {
        (**self).bounds()
    }
    fn ellipse_average(&self, region: &PlanarEllipse) -> Option<Coefficients> {
        (**self).ellipse_average(region)
    }
    fn displacement_scale(&self, region: &PlanarEllipse) -> Option<f64> {
        (**self).displacement_scale(region)
    }
    fn ellipse_average_in_chart(
        &self,
        region: &PlanarEllipse,
        chart: &UvChart,
    ) -> Option<Coefficients> {
        (**self).ellipse_average_in_chart(region, chart)
    }
    #[inline]
    fn averaged_at_points_in_chart(
        &self,
        xs: &[glam::DVec3],
        chart: &UvChart,
        out: &mut [Coefficients],
    ) -> bool {
        (**self).averaged_at_points_in_chart(xs, chart, out)
    }
    #[inline]
    fn averaged(&self, p: &P) -> Coefficients {
        (**self).averaged(p)
    }
    #[inline]
    fn coefficients_of_mean(&self, mean: Coefficients) -> Coefficients {
        (**self).coefficients_of_mean(mean)
    }
    #[inline]
    fn averaged_at_point(&self, x: glam::DVec3) -> Option<Coefficients> {
        (**self).averaged_at_point(x)
    }
    #[inline]
    fn averaged_at_points(&self, xs: &[glam::DVec3], out: &mut [Coefficients]) -> bool {
        (**self).averaged_at_points(xs, out)
    }
}
