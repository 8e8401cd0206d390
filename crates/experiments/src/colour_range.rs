//! The log colour range of the beam maps' false-colour PNGs, shared by the maps of one
//! figure and by their plots.

/// The log colour range of a beam map's PNG, from `min` (bottom of the colour bar) to `max`
/// (top). The maps of one figure share one, so that equal colours are equal exitances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourRange {
    /// Exitance at the bottom of the colour bar (> 0).
    pub min: f64,
    /// Exitance at the top.
    pub max: f64,
}

impl ColourRange {
    /// Decades shown below a map's largest value.
    pub const DECADES: f64 = 6.0;

    /// The range of `values`: their largest value and [`Self::DECADES`] below it (or their
    /// smallest positive value, if higher).
    pub fn of(values: &[f64]) -> ColourRange {
        Self::spanning(values, Self::DECADES)
    }

    /// The range from the largest finite value of `values` down `decades` (or to their
    /// smallest positive value, if higher); 1 and 0.1 when no value is positive.
    pub fn spanning(values: &[f64], decades: f64) -> ColourRange {
        let max = values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let max = if max > 0.0 { max } else { 1.0 };
        let min_pos = values
            .iter()
            .copied()
            .filter(|&v| v > 0.0 && v.is_finite())
            .fold(f64::INFINITY, f64::min);
        let min = min_pos.max(max * 10f64.powf(-decades));
        ColourRange {
            min: if min.is_finite() && min < max {
                min
            } else {
                max / 10.0
            },
            max,
        }
    }
}
