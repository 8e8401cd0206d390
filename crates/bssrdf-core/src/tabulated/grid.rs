//! The grid of the tabulated half-space profile: refractive indices, albedos and radii.

/// Relative refractive indices η = n_medium / n_outside of the table's planes: 1 to 1.6 in
/// steps of 0.05, dense enough that cubic interpolation between planes is well below the
/// table's noise (the leave-one-out check in `tests/tabulated.rs` at twice this spacing is
/// within it; `docs/tabulated-profile.md`).
pub const ETAS: [f64; 13] = [
    1.0, 1.05, 1.1, 1.15, 1.2, 1.25, 1.3, 1.35, 1.4, 1.45, 1.5, 1.55, 1.6,
];

/// The planes of an evenly spaced η grid (`etas`, at least two) that bracket `eta`, and the
/// weight of the upper one: `(q, f)` with `eta ≈ (1 − f)·etas[q] + f·etas[q + 1]`, `eta`
/// clamped to the grid (and the first plane for a non-finite `eta`). Used by the angular
/// coupling's and the oblique shape's data, which are linear between their planes.
pub fn eta_bracket(etas: &[f64], eta: f64) -> (usize, f64) {
    let step = etas[1] - etas[0];
    let last = etas.len() - 1;
    let pe = if eta.is_finite() {
        ((eta - etas[0]) / step).clamp(0.0, last as f64)
    } else {
        0.0
    };
    let q = (pe as usize).min(last - 1);
    (q, pe - q as f64)
}

/// Number of albedo rows.
pub const N_ALBEDO: usize = 40;
/// Smallest tabulated `s = √(1 − α)` (α = 0.999975); larger albedos use this row.
pub const S_MIN: f64 = 0.005;

/// `s_k = √(1 − α_k)` of row `k`, geometric from [`S_MIN`] to 1 (dense near α = 1, where
/// the profiles change fastest and translucent materials live: α = 0.999 is s ≈ 0.032).
pub fn s_of_row(k: usize) -> f64 {
    s_of_row_in(k, N_ALBEDO)
}

/// Single-scattering albedo α_k of row `k`.
pub fn albedo_of_row(k: usize) -> f64 {
    albedo_of_row_in(k, N_ALBEDO)
}

/// `s_k` of row `k` of a grid of `rows` rows with the same law (geometric from [`S_MIN`] to 1;
/// the slab table uses fewer rows than the half-space table).
pub fn s_of_row_in(k: usize, rows: usize) -> f64 {
    if k + 1 >= rows {
        return 1.0;
    }
    S_MIN * (1.0 / S_MIN).powf(k as f64 / (rows - 1) as f64)
}

/// Single-scattering albedo of row `k` of a grid of `rows` rows ([`s_of_row_in`]).
pub fn albedo_of_row_in(k: usize, rows: usize) -> f64 {
    let s = s_of_row_in(k, rows);
    1.0 - s * s
}

// The slab table's grid (`super::slab`): thicknesses, refractive indices and albedo rows.

/// Optical thicknesses σt·d (mean free paths) of the slab table's planes.
pub const SLAB_THICKNESSES: [f64; 7] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
/// Relative refractive indices of the slab table's planes (uniform; cubic interpolation between).
pub const SLAB_ETAS: [f64; 5] = [1.0, 1.15, 1.3, 1.45, 1.6];
/// Number of slab albedo rows: `s = √(1 − α)` geometric from [`S_MIN`] to 1.
pub const SLAB_ROWS: usize = 16;

/// `s = √(1 − α)` of slab row `k`.
pub fn slab_s_of_row(k: usize) -> f64 {
    s_of_row_in(k, SLAB_ROWS)
}

/// Albedo α of slab row `k`.
pub fn slab_albedo_of_row(k: usize) -> f64 {
    albedo_of_row_in(k, SLAB_ROWS)
}

/// Radial bins in optical units x = σt·r: bin 0 is `[0, X_FIRST)`, then [`BINS_PER_DECADE`]
/// geometric bins per decade up to [`X_LAST`]; exits beyond count in the totals only.
pub const X_FIRST: f64 = 1e-3;
/// Outer edge of the last bin.
pub const X_LAST: f64 = 1e3;
/// Geometric bins per decade.
pub const BINS_PER_DECADE: usize = 20;
/// Number of radial bins.
pub const N_BINS: usize = 1 + 6 * BINS_PER_DECADE;

/// Edge `j` of the radial bins (`edge(0) = 0`, `edge(N_BINS) = X_LAST`).
#[inline]
pub fn edge(j: usize) -> f64 {
    radii().edges[j]
}

/// The bins' edges and centres, computed once: they are read in every evaluation and in the
/// table's preparation, where `powf` per read was most of the load time.
struct Radii {
    edges: [f64; N_BINS + 1],
    centres: [f64; N_BINS],
    /// ln of each edge (edge 0 is 0: −∞) and centre.
    ln_edges: [f64; N_BINS + 1],
    ln_centres: [f64; N_BINS],
}

fn radii() -> &'static Radii {
    static RADII: std::sync::OnceLock<Radii> = std::sync::OnceLock::new();
    RADII.get_or_init(|| {
        let edges: [f64; N_BINS + 1] = std::array::from_fn(|j| {
            if j == 0 {
                0.0
            } else {
                X_FIRST * 10f64.powf((j - 1) as f64 / BINS_PER_DECADE as f64)
            }
        });
        let centres = std::array::from_fn(|j| {
            if j == 0 {
                0.5 * X_FIRST
            } else {
                (edges[j] * edges[j + 1]).sqrt()
            }
        });
        Radii {
            edges,
            centres,
            ln_edges: edges.map(f64::ln),
            ln_centres: centres.map(f64::ln),
        }
    })
}

/// The bin holding optical radius `x`, or `None` beyond [`X_LAST`].
#[inline]
pub fn bin_of(x: f64) -> Option<usize> {
    if x < X_FIRST {
        return Some(0);
    }
    let j = 1 + ((x / X_FIRST).log10() * BINS_PER_DECADE as f64) as usize;
    (j < N_BINS).then_some(j)
}

/// ln [`edge`]`(j)`.
#[inline]
pub(crate) fn ln_edge(j: usize) -> f64 {
    radii().ln_edges[j]
}

/// ln [`centre`]`(j)`.
#[inline]
pub(crate) fn ln_centre(j: usize) -> f64 {
    radii().ln_centres[j]
}

/// The representative radius of bin `j`: the geometric mean of its edges (0's: X_FIRST / 2).
#[inline]
pub fn centre(j: usize) -> f64 {
    radii().centres[j]
}

/// Area of the annulus of bin `j` (optical units²).
pub fn annulus_area(j: usize) -> f64 {
    let (a, b) = (edge(j), edge(j + 1));
    std::f64::consts::PI * (b * b - a * a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bracketing planes and weight: inside, at the ends, outside (clamped), not finite.
    #[test]
    fn eta_bracket_finds_the_planes_around_eta() {
        let etas = [1.0, 1.1, 1.2, 1.3];
        let (q, f) = eta_bracket(&etas, 1.15);
        assert!(q == 1 && (f - 0.5).abs() < 1e-12, "{q} {f}");
        assert_eq!(eta_bracket(&etas, 1.0), (0, 0.0));
        let (q, f) = eta_bracket(&etas, 1.3);
        assert!(q == 2 && (f - 1.0).abs() < 1e-12, "{q} {f}");
        assert_eq!(eta_bracket(&etas, 0.5), (0, 0.0));
        let (q, f) = eta_bracket(&etas, 3.0);
        assert!(q == 2 && (f - 1.0).abs() < 1e-12, "{q} {f}");
        assert_eq!(eta_bracket(&etas, f64::NAN), (0, 0.0));
    }
}
