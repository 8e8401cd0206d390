//! The point-lookup baselines: Jensen et al. (JMLH01) and d'Eon & Irving (dEI11), as the
//! paper's §4 describes them.

use crate::estimator_output::Region;
use crate::field::{CoefficientField, Coefficients};
use crate::region_average::Probe;
use crate::surface::SurfaceQuery;

/// Jensen et al.: the coefficients at one point. The paper's §4 uses the incident point x_i
/// as JMLH01 suggests (`jensen-in`), except for its beam plots (Figure 4), which use the
/// exitant point x_o (`jensen-out`), since with a fixed x_i the result would be homogeneous.
pub(crate) fn single_point<S, F>(probe: &mut Probe<'_, S, F>, at_incident: bool) -> Coefficients
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
{
    probe.diag.region = Region::Point;
    let p = if at_incident { probe.x_i } else { probe.x_o };
    probe.lookup(p)
}

/// d'Eon & Irving, read as the endpoint mean ½(σ(x_i) + σ(x_o)) (`endpoints`).
///
/// The paper (§4) says only that this heuristic "take[s] averages of coefficients between
/// incident and exitant points"; dEI11's own rule was not checked (docs/physics.md#heuristics, unchecked).
/// The two-lookup endpoint mean is the literal reading and the likelier one, so it is the
/// paper's baseline here; the chord mean is a separate estimator (`segment`), not attributed
/// to dEI11.
pub(crate) fn endpoints<S, F>(probe: &mut Probe<'_, S, F>) -> Coefficients
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
{
    probe.diag.region = Region::Endpoints;
    probe.endpoints()
}
