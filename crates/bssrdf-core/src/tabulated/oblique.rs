//! The radial shape for light entering at an angle: how the exitance of a half-space around
//! the point of entry changes with the incident and exit cosines, beyond the angular coupling
//! (docs/oblique-incidence.md).
//!
//! The tabulated profile R(r) is the response to light entering along the normal, and the
//! angular coupling T(α, μ_i, μ_o) ([`super::angular`]) scales it so that its integral over the
//! surface is exact for every pair of directions. The radial shape itself changes with the
//! angles: light arriving obliquely turns back to the surface after fewer events and leaves
//! closer to where it entered, so a grazing pair's response is concentrated near the entry and
//! its far tail is lower than the normal-incidence shape scaled by T. Under a local light that
//! tail carries light entering far from the view into it (the 4 × 4 quad over a half-space was
//! 1.19× the path tracer with T alone).
//!
//! The shape factor M(x; α, μ_i, μ_o), x = σt' r in (reduced) mean free paths, is the ratio of
//! the pair's radial distribution to the normal-incidence one:
//!
//! M_jk(b) = [P_jk(b) / Σ_b P_jk(b)] / [m_n(b) / Σ_b m_n(b)],
//!
//! P_jk(b) the simulated power falling from cosine bin j that leaves into bin k through radial
//! bin b ([`super::oblique_file`]), symmetrised over (j, k) as the coupling's is, and m_n(b)
//! the mass of the normal-incidence profile (the tabulated profile itself, at the same η,
//! albedo and orders) in the same annulus. S is multiplied by T · M. M is interpolated
//! linearly in ln x between the radial bins' centres (constant beyond the outer ones), and its
//! node values are set by a fixed point so that the interpolant's mass in every radial bin is
//! the simulated one: ∫ 2πr R(r) M dr = ∫ 2πr R(r) dr for every pair, and T keeps its meaning.
//! Across cosine bins it is bilinear in μ² between the bins' centres (with T's cells), linear
//! between albedo rows and between the η planes.
//!
//! Reciprocity: M is symmetric in (μ_i, μ_o) bit for bit (the cells order their cosines), and
//! r is symmetric in the two points. The azimuthal moment the data also holds is not used
//! (docs/oblique-incidence.md, "What is left").

use std::sync::OnceLock;

use super::angular::Cells;
use super::angular_file::N_MU;
use super::grid::{N_BINS, annulus_area, centre};
use super::half_space::{AlbedoRow, TabulatedTerm, row_position};
use super::oblique_file::{
    ALPHA_MAX, N_HARMONICS, N_RADII, N_ROWS, OBLIQUE_ETAS, ObliqueData, ObliquePlane, PLANE_LEN,
    index, radial_bin, radial_edge,
};
use crate::model::Scattering;

/// The data file built into the crate (regenerate with `het-bssrdf tabulate --oblique`).
static DATA: &[u8] = include_bytes!("../../data/oblique-shape-v1.bin");

/// The built-in data, parsed once.
pub fn oblique_data() -> &'static ObliqueData {
    static PARSED: OnceLock<ObliqueData> = OnceLock::new();
    PARSED.get_or_init(|| {
        ObliqueData::from_bytes(DATA).expect("the built-in oblique shape data is valid (tested)")
    })
}

/// ln of the radial nodes: the geometric centres of the radial bins, the first at half the
/// inner bin's edge and the last (unbounded bin) at 10^(1/4) times its inner edge.
fn ln_nodes() -> &'static [f64; N_RADII] {
    static NODES: OnceLock<[f64; N_RADII]> = OnceLock::new();
    NODES.get_or_init(|| {
        std::array::from_fn(|b| match b {
            0 => (0.5 * radial_edge(1)).ln(),
            _ if b + 1 == N_RADII => (radial_edge(b) * 10f64.powf(0.25)).ln(),
            _ => 0.5 * (radial_edge(b).ln() + radial_edge(b + 1).ln()),
        })
    })
}

/// The geometric midpoints between consecutive radial nodes, exp((ln x_k + ln x_{k+1}) / 2).
fn midpoints() -> &'static [f64; N_RADII - 1] {
    static MID: OnceLock<[f64; N_RADII - 1]> = OnceLock::new();
    MID.get_or_init(|| {
        let n = ln_nodes();
        std::array::from_fn(|k| (0.5 * (n[k] + n[k + 1])).exp())
    })
}

/// Where `ln_x` falls among the nodes: the lower node and the weight of the next (constant
/// beyond the outer nodes).
#[inline]
fn radial_position(ln_x: f64) -> (usize, f64) {
    let n = ln_nodes();
    if ln_x.is_nan() || ln_x <= n[0] {
        return (0, 0.0);
    }
    if ln_x >= n[N_RADII - 1] {
        return (N_RADII - 2, 1.0);
    }
    // The nodes are uniform in ln x from node 1 to node N − 2 (a step of ln 10 / PER_DECADE):
    // the interval from that, then one step either way where rounding put it off by one.
    let mut i = if ln_x < n[1] {
        0
    } else {
        let step = n[2] - n[1];
        (1 + ((ln_x - n[1]) / step) as usize).min(N_RADII - 2)
    };
    if i > 0 && ln_x < n[i] {
        i -= 1;
    } else if i + 2 < N_RADII && ln_x >= n[i + 1] {
        i += 1;
    }
    (i, (ln_x - n[i]) / (n[i + 1] - n[i]))
}

/// A radial bin counts as sparse when its symmetrised mass has a relative standard error above
/// this: its M is carried over from the nearest bin inward.
const MAX_REL_SE: f64 = 0.25;
/// The same for the forward shift's coefficient (a ratio of two noisy sums).
const MAX_REL_SE_SHIFT: f64 = 0.1;
/// Bound on the forward shift's coefficient C (the data stay below 4).
const C_MAX: f64 = 8.0;
/// Passes of the fixed point that conserves each radial bin's mass.
const PASSES: usize = 6;

/// The oblique shape factor M for one η and choice of scattering orders, with the forward
/// shift's coefficients: per albedo row, pair of cosine bins and radial node, the values a
/// lookup reads together, side by side in 32-byte records. About 460 KB; built once per
/// material (a few milliseconds).
#[derive(Debug, Clone, PartialEq)]
pub struct ObliqueShape {
    /// `[row][j][k][node]`.
    nodes: Vec<NodeValues>,
}

/// What one lookup reads at one corner (row, j, k) and radial node, side by side so that a
/// corner's two nodes share a cache line: M (symmetric in j, k), C_n of light entering in
/// bin j and leaving in bin k, C_n of the reverse (k to j), and a zero that pads the record
/// to 32 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
struct NodeValues([f32; 8]);

impl ObliqueShape {
    /// M at relative index `eta` (clamped to [1, 1.6]; linear between the data's planes) for
    /// the orders `scattering` selects.
    pub fn new(eta: f64, scattering: Scattering) -> Self {
        let (single, multiple) = (scattering.includes_single(), scattering.includes_multiple());
        let (q, f) = super::grid::eta_bracket(&OBLIQUE_ETAS, eta);
        let lo = Self::plane(q, single, multiple);
        let mix = |lo: &[f64], hi: Option<&[f64]>| -> Vec<f32> {
            match hi {
                None => lo.iter().map(|&a| a as f32).collect(),
                Some(hi) => lo
                    .iter()
                    .zip(hi)
                    .map(|(a, b)| ((1.0 - f) * a + f * b) as f32)
                    .collect(),
            }
        };
        let (m, c) = if f == 0.0 {
            (mix(&lo.0, None), mix(&lo.1, None))
        } else {
            let hi = Self::plane(q + 1, single, multiple);
            (mix(&lo.0, Some(&hi.0)), mix(&lo.1, Some(&hi.1)))
        };
        // Interleave: each record holds M, C(j → k) and C(k → j) of its corner and node.
        let len = N_ROWS * N_MU * N_MU * N_RADII;
        let mut nodes = vec![NodeValues::default(); len];
        for row in 0..N_ROWS {
            for j in 0..N_MU {
                for k in 0..N_MU {
                    let at = |a: usize, b: usize| ((row * N_MU + a) * N_MU + b) * N_RADII;
                    let (jk, kj) = (at(j, k), at(k, j));
                    for b in 0..N_RADII {
                        let v = &mut nodes[jk + b].0;
                        v[0] = m[jk + b];
                        for h in 0..N_HARMONICS {
                            v[1 + h] = c[(jk + b) * N_HARMONICS + h];
                            v[4 + h] = c[(kj + b) * N_HARMONICS + h];
                        }
                    }
                }
            }
        }
        Self { nodes }
    }

    /// M's and C's node values at the data's plane `q` (`[row][j][k][node]`, f64).
    fn plane(q: usize, single: bool, multiple: bool) -> (Vec<f64>, Vec<f64>) {
        let data = &oblique_data().planes[q];
        let kinds = [single, multiple];
        let ln_fine: Vec<f64> = (0..N_BINS).map(|f| centre(f).ln()).collect();
        let coarse_of: Vec<usize> = (0..N_BINS).map(|f| radial_bin(centre(f))).collect();
        // The interpolation weights of every fine bin's centre on the nodes.
        let fine_pos: Vec<(usize, f64)> = ln_fine.iter().map(|&l| radial_position(l)).collect();
        let per_pair = N_RADII;
        let mut out = vec![1.0; N_ROWS * N_MU * N_MU * per_pair];
        let len = N_ROWS * N_MU * N_MU * per_pair;
        let mut shift = vec![0.0; N_HARMONICS * len];
        let sin_mean: Vec<[f64; N_HARMONICS]> = (0..N_MU)
            .map(|j| std::array::from_fn(|h| mean_sine_power(j, h + 1)))
            .collect();
        for row in 0..N_ROWS {
            let alpha = super::grid::albedo_of_row_in(row, N_ROWS).min(ALPHA_MAX);
            let data_row = data_row_of(row);
            // The normal-incidence profile's mass per fine bin (σt = 1).
            let term = TabulatedTerm::new(1.0, alpha, data.eta, single, multiple);
            let fine: Vec<f64> = (0..N_BINS)
                .map(|f| term.bin_value(f) * annulus_area(f))
                .collect();
            let fine_total: f64 = fine.iter().sum();
            if fine_total.is_nan() || fine_total <= 0.0 {
                continue;
            }
            let mut normal = [0.0; N_RADII];
            for (f, &mf) in fine.iter().enumerate() {
                normal[coarse_of[f]] += mf / fine_total;
            }
            for j in 0..N_MU {
                for k in j..N_MU {
                    let masses = pair_masses(data, kinds, (data_row, j, k));
                    let total: f64 = masses.iter().map(|m| m.0).sum();
                    if total.is_nan() || total <= 0.0 {
                        continue;
                    }
                    // Targets: the pair's mass fraction per radial bin; a sparse bin takes the
                    // ratio to the normal shape of the nearest dense bin inward.
                    let mut target = [0.0; N_RADII];
                    let mut ratio = 1.0;
                    for b in 0..N_RADII {
                        let (v, var) = masses[b];
                        if v > 0.0 && var.sqrt() <= MAX_REL_SE * v && normal[b] > 0.0 {
                            ratio = (v / total) / normal[b];
                        }
                        target[b] = ratio * normal[b];
                    }
                    let mut node = [1.0f64; N_RADII];
                    for (b, n) in node.iter_mut().enumerate() {
                        if normal[b] > 0.0 {
                            *n = target[b] / normal[b];
                        }
                    }
                    let integrals = |node: &[f64; N_RADII]| {
                        let mut got = [0.0; N_RADII];
                        for f in 0..N_BINS {
                            let (i, w) = fine_pos[f];
                            let m = (1.0 - w) * node[i] + w * node[i + 1];
                            got[coarse_of[f]] += fine[f] / fine_total * m;
                        }
                        got
                    };
                    for _ in 0..PASSES {
                        let got = integrals(&node);
                        for b in 0..N_RADII {
                            if got[b] > 0.0 && target[b] > 0.0 {
                                node[b] *= target[b] / got[b];
                            }
                        }
                    }
                    // The pair's total is T's: M integrates to 1 against the normal shape.
                    let sum: f64 = integrals(&node).iter().sum();
                    if sum > 0.0 && sum.is_finite() {
                        node.iter_mut().for_each(|n| *n /= sum);
                    }
                    for (a, c) in [(j, k), (k, j)] {
                        let at = ((row * N_MU + a) * N_MU + c) * per_pair;
                        for b in 0..N_RADII {
                            out[at + b] = node[b].max(0.0);
                        }
                        let value = forward_shift(data, kinds, (data_row, a, c), &sin_mean[a]);
                        for b in 0..N_RADII {
                            for h in 0..N_HARMONICS {
                                shift[(at + b) * N_HARMONICS + h] = value[b][h];
                            }
                        }
                    }
                }
            }
        }
        (out, shift)
    }

    /// M(x; α, μ_i, μ_o) (unitless, finite and ≥ 0 for every input) at `x` mean free paths
    /// (σt' r): see the module docs. Exactly symmetric in (`mu_i`, `mu_o`). Non-finite
    /// arguments give 1.
    pub fn factor(&self, alpha: f64, x: f64, mu_i: f64, mu_o: f64) -> f64 {
        self.pair([alpha], [x], mu_i, mu_o)[0].m
    }

    /// The forward shift's coefficients C_n(x; α, μ_i → μ_o), n = 1, 2, 3 (unitless, finite,
    /// |C_n| ≤ 8) of light entering at cosine `mu_i` and leaving at `mu_o`, `x` mean free
    /// paths from its entry: the exit point's azimuthal density about the entry point is
    /// ∝ 1 + Σ_n C_n · sinⁿ θ_i · cos nφ, φ measured from the incident light's direction of
    /// travel along the surface (Fourier moments of the simulated exits, exit azimuth
    /// averaged; docs/oblique-incidence.md). Not symmetric: the reciprocal term of the pair is
    /// `shift(alpha, x, mu_o, mu_i)`. Non-finite arguments give 0.
    pub fn shift(&self, alpha: f64, x: f64, mu_i: f64, mu_o: f64) -> [f64; N_HARMONICS] {
        self.pair([alpha], [x], mu_i, mu_o)[0].incident
    }

    /// Where `x` mean free paths (σt' r) falls among the forward shift's radial nodes: the
    /// lower node k and the weight w ∈ [0, 1] of node k + 1, k + 1 < [`N_RADII`]; [`Self::shift`]
    /// is linear in w between the two nodes' values ([`Self::shifts_at_node`]) and constant
    /// beyond the outer nodes. NaN and x ≤ 0 give (0, 0).
    pub fn radial_node(x: f64) -> (usize, f64) {
        radial_position(x.max(0.0).ln())
    }

    /// The radial node nearest `x` mean free paths (σt' r) in ln x: [`Self::radial_node`]'s
    /// k where its weight is below ½, else k + 1 (0 for NaN and x ≤ 0; the last node beyond
    /// it). Found by comparing x with the geometric midpoints between the nodes, without the
    /// logarithm.
    pub fn nearest_node(x: f64) -> usize {
        midpoints().iter().filter(|&&m| x >= m).count()
    }

    /// Both sides' C_n at radial node `node` (clamped to the last): `(shift(α, x, μ_i, μ_o),
    /// shift(α, x, μ_o, μ_i))` at that node's radius x (unitless, finite, |C_n| ≤ 8), the row
    /// and cells found once (the cells read by [`Self::pair`]'s own lookup). What a caller
    /// that reads the shift node by node needs (the probes' azimuthal guide). Non-finite
    /// arguments give 0.
    pub fn shifts_at_node(
        &self,
        alpha: f64,
        node: usize,
        mu_i: f64,
        mu_o: f64,
    ) -> [[f64; N_HARMONICS]; 2] {
        if !(alpha.is_finite() && mu_i.is_finite() && mu_o.is_finite()) {
            return [[0.0; N_HARMONICS]; 2];
        }
        // Node k is (k, 0) between nodes k and k + 1, the last node (N − 2, 1).
        let (i, w) = if node + 1 < N_RADII {
            (node, 0.0)
        } else {
            (N_RADII - 2, 1.0)
        };
        let cells = Cells::new(mu_i, mu_o);
        let (r0, fr) = row_position(alpha, N_ROWS);
        let mut v = [0.0; 8];
        for (r, wr) in [(r0, 1.0 - fr), (r0 + 1, fr)] {
            if wr == 0.0 {
                continue;
            }
            let got = self.corners(r * N_MU * N_MU, &cells, i, w);
            v.iter_mut().zip(got).for_each(|(v, g)| *v += wr * g);
        }
        let (_, incident, exitant) = sides(&v, mu_i, mu_o);
        [clean_shift(incident), clean_shift(exitant)]
    }

    /// M and both sides' shift coefficients for several channels (albedo and optical radius
    /// each) at the same pair of cosines: the cells are found once, each channel's row and
    /// radial position once, and a channel equal to the previous one reuses its values.
    /// `pair(…, mu_i, mu_o)` and `pair(…, mu_o, mu_i)` give the same M and swapped shift
    /// coefficients, bit for bit.
    pub fn pair<const N: usize>(
        &self,
        alpha: [f64; N],
        x: [f64; N],
        mu_i: f64,
        mu_o: f64,
    ) -> [PairFactors; N] {
        self.pair_on(AlbedoRow::of_each(alpha), x, mu_i, mu_o)
    }

    /// [`ObliqueShape::pair`] at albedos already placed on the grid (`None`: a non-finite
    /// albedo, which reads [`PairFactors::NEUTRAL`]).
    pub(crate) fn pair_on<const N: usize>(
        &self,
        rows: [Option<AlbedoRow>; N],
        x: [f64; N],
        mu_i: f64,
        mu_o: f64,
    ) -> [PairFactors; N] {
        let mut out = [PairFactors::NEUTRAL; N];
        if !(mu_i.is_finite() && mu_o.is_finite()) {
            return out;
        }
        let cells = Cells::new(mu_i, mu_o);
        for ch in 0..N {
            let same = ch > 0 && rows[ch] == rows[ch - 1] && x[ch].to_bits() == x[ch - 1].to_bits();
            out[ch] = if same {
                out[ch - 1]
            } else if let (Some(row), false) = (rows[ch], x[ch].is_nan()) {
                let (r0, fr) = row.position(N_ROWS);
                let (i, w) = radial_position(x[ch].max(0.0).ln());
                let rows: &[(usize, f64)] = if fr == 0.0 {
                    &[(r0, 1.0)]
                } else {
                    &[(r0, 1.0 - fr), (r0 + 1, fr)]
                };
                let mut v = [0.0; 8];
                for &(r, wr) in rows {
                    let got = self.corners(r * N_MU * N_MU, &cells, i, w);
                    v.iter_mut().zip(got).for_each(|(v, g)| *v += wr * g);
                }
                let (m, incident, exitant) = sides(&v, mu_i, mu_o);
                PairFactors {
                    m: if m.is_finite() { m.max(0.0) } else { 1.0 },
                    incident: clean_shift(incident),
                    exitant: clean_shift(exitant),
                }
            } else {
                PairFactors::NEUTRAL
            };
        }
        out
    }

    /// The records of one row (`base` its first entry) interpolated bilinearly over `cells`
    /// (the lower cosine's bin first) and linearly between radial nodes `i` and `i + 1` with
    /// weight `w`: M, C_n from the lower cosine to the higher, C_n back, and the padding's 0.
    #[inline]
    fn corners(&self, base: usize, cells: &Cells, i: usize, w: f64) -> [f64; 8] {
        let mut out = [0.0; 8];
        for ((a, c), wac) in cells.corners() {
            let at = (base + a * N_MU + c) * N_RADII + i;
            let (lo, hi) = (&self.nodes[at].0, &self.nodes[at + 1].0);
            for ((o, &l), &h) in out.iter_mut().zip(lo).zip(hi) {
                *o += wac * ((1.0 - w) * f64::from(l) + w * f64::from(h));
            }
        }
        out
    }
}

/// M and the two sides' C_n from interpolated records ([`ObliqueShape::corners`], whose cells
/// order the cosines): the incident side's C_n is the one from the lower cosine when
/// `mu_i ≤ mu_o`, else the one back. Reading in the cells' order and swapping after makes
/// swapped cosines give swapped sides bit for bit.
#[inline]
fn sides(v: &[f64; 8], mu_i: f64, mu_o: f64) -> (f64, [f64; N_HARMONICS], [f64; N_HARMONICS]) {
    let up = [v[1], v[2], v[3]];
    let down = [v[4], v[5], v[6]];
    if mu_i <= mu_o {
        (v[0], up, down)
    } else {
        (v[0], down, up)
    }
}

/// Shift coefficients clamped to ±[`C_MAX`], a non-finite one 0.
fn clean_shift(c: [f64; N_HARMONICS]) -> [f64; N_HARMONICS] {
    c.map(|v| {
        if v.is_finite() {
            v.clamp(-C_MAX, C_MAX)
        } else {
            0.0
        }
    })
}

/// The mass of the unordered incidence/exit pair {j, k} at `data_row` (`(data_row, j, k)`)
/// per radial bin, with its variance: the mean of (j, k) and (k, j) over the scattering
/// orders `kinds` selects.
fn pair_masses(
    data: &ObliquePlane,
    kinds: [bool; 2],
    (data_row, j, k): (usize, usize, usize),
) -> Vec<(f64, f64)> {
    let mass = |b: usize| -> (f64, f64) {
        let mut v = 0.0;
        let mut var = 0.0;
        for (kind, _) in kinds.iter().enumerate().filter(|(_, on)| **on) {
            for (a, c) in [(j, k), (k, j)] {
                let i = index(kind, data_row, a, c, b);
                v += 0.5 * f64::from(data.p[i]);
                var += 0.25 * f64::from(data.p_se[i]).powi(2);
            }
        }
        // For j = k both terms are the same entry: its variance counted
        // twice at a quarter is half of it, undercounted by 2.
        (v, if j == k { 2.0 * var } else { var })
    };
    (0..N_RADII).map(mass).collect()
}

/// The data row whose shape albedo row `row` takes: itself, or for the rows above ALPHA_MAX
/// the row at it (their paths were cut earlier).
fn data_row_of(row: usize) -> usize {
    if super::grid::albedo_of_row_in(row, N_ROWS) > ALPHA_MAX {
        (0..N_ROWS)
            .find(|&r| super::grid::albedo_of_row_in(r, N_ROWS) <= ALPHA_MAX)
            .unwrap_or(row)
    } else {
        row
    }
}

/// The forward shift from incidence bin a to exit bin c at `data_row` (`(data_row, a, c)`),
/// for the scattering orders `kinds` selects: C_n = 2⟨cos nφ⟩ / ⟨sinⁿ θ⟩_a per radial bin
/// (`sin_mean` is ⟨sinⁿ θ⟩_a), from the bins whose mass is known to 10 %; a sparser bin keeps
/// the values of the nearest one inward.
fn forward_shift(
    data: &ObliquePlane,
    kinds: [bool; 2],
    (data_row, a, c): (usize, usize, usize),
    sin_mean: &[f64; N_HARMONICS],
) -> [[f64; N_HARMONICS]; N_RADII] {
    let mut out = [[0.0; N_HARMONICS]; N_RADII];
    let mut value = [0.0; N_HARMONICS];
    for (b, out) in out.iter_mut().enumerate() {
        let (mut v, mut cos, mut var) = (0.0, [0.0; N_HARMONICS], 0.0);
        for kind in (0..2).filter(|&kind| kinds[kind]) {
            let i = index(kind, data_row, a, c, b);
            v += f64::from(data.p[i]);
            for (h, cos) in cos.iter_mut().enumerate() {
                *cos += f64::from(data.p_cos[h * PLANE_LEN + i]);
            }
            var += f64::from(data.p_se[i]).powi(2);
        }
        if v > 0.0 && var.sqrt() <= MAX_REL_SE_SHIFT * v {
            for h in 0..N_HARMONICS {
                value[h] = (2.0 * cos[h] / v / sin_mean[h]).clamp(-C_MAX, C_MAX);
            }
        }
        *out = value;
    }
    out
}

/// What [`ObliqueShape::pair`] reads for one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairFactors {
    /// The radial part M (symmetric in the two cosines).
    pub m: f64,
    /// C_n of the light entering at the first cosine and leaving at the second.
    pub incident: [f64; N_HARMONICS],
    /// C_n of the reverse: entering at the second cosine, leaving at the first.
    pub exitant: [f64; N_HARMONICS],
}

impl PairFactors {
    /// M = 1 and no shift: what a channel without a valid albedo reads.
    pub const NEUTRAL: PairFactors = PairFactors {
        m: 1.0,
        incident: [0.0; N_HARMONICS],
        exitant: [0.0; N_HARMONICS],
    };
}

/// ⟨sinⁿ θ⟩ over the cosine bin `j` (μ² = u uniform in [a, b] = [j/N, (j + 1)/N]):
/// N / (n/2 + 1) · [(1 − a)^{n/2 + 1} − (1 − b)^{n/2 + 1}].
fn mean_sine_power(j: usize, n: usize) -> f64 {
    let (a, b) = (j as f64 / N_MU as f64, (j + 1) as f64 / N_MU as f64);
    let e = n as f64 / 2.0 + 1.0;
    N_MU as f64 / e * ((1.0 - a).powf(e) - (1.0 - b).powf(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_data_round_trips_and_rejects_damage() {
        let d = oblique_data();
        let bytes = d.to_bytes();
        assert_eq!(
            bytes, DATA,
            "the built-in file is what its parse writes back"
        );
        let mut bad = bytes.clone();
        bad[0] = b'X';
        assert!(ObliqueData::from_bytes(&bad).is_err());
        let mut trailing = bytes;
        trailing.push(0);
        assert!(ObliqueData::from_bytes(&trailing).is_err());
    }

    #[test]
    fn factor_is_symmetric_bit_for_bit_and_finite_everywhere() {
        let values = [
            -1.0,
            0.0,
            1e-9,
            0.1,
            0.3,
            0.5,
            0.77,
            0.999,
            1.0,
            2.0,
            f64::NAN,
            f64::INFINITY,
        ];
        let radii = [
            -1.0,
            0.0,
            1e-6,
            0.05,
            0.3,
            2.0,
            40.0,
            1e4,
            f64::INFINITY,
            f64::NAN,
        ];
        for eta in [1.0, 1.3, 1.6, 3.0, f64::NAN] {
            for &scattering in Scattering::ALL {
                let m = ObliqueShape::new(eta, scattering);
                for &alpha in &values {
                    for &x in &radii {
                        for &a in &values {
                            for &b in &values {
                                let (p, q) = (m.factor(alpha, x, a, b), m.factor(alpha, x, b, a));
                                assert!(p.is_finite() && p >= 0.0, "{eta} {alpha} {x} {a} {b}");
                                assert_eq!(p.to_bits(), q.to_bits(), "{eta} {alpha} {x} {a} {b}");
                            }
                        }
                    }
                }
            }
        }
    }

    /// M keeps T's meaning: for pairs of cosines at and between the bins' centres, η on and
    /// between the planes and both choices of orders, ∫ 2πx R(x) M(x) dx over the
    /// normal-incidence profile R equals ∫ 2πx R(x) dx within 0.6 % at albedos of 0.9 and
    /// above (the fixed point makes each row exact; between rows, M's rows are mixed against
    /// a profile whose shape is not theirs). At lower albedos the rows' shapes differ more:
    /// within 6 % (measured: 4.9 % at α = 0.3, normal incidence and exit, all orders). The
    /// quadrature is independent of the fixed point's (40 points per radial bin).
    #[test]
    fn shape_factor_conserves_every_pair() {
        use crate::RadialProfile;
        let mut worst: f64 = 0.0;
        for eta in [1.0, 1.3, 1.45] {
            for (single, multiple, scattering) in [
                (false, true, Scattering::Multiple),
                (true, true, Scattering::All),
            ] {
                let m = ObliqueShape::new(eta, scattering);
                for alpha in [0.3, 0.5, 0.7, 0.9, 0.99, 0.999] {
                    let term = TabulatedTerm::new(1.0, alpha, eta, single, multiple);
                    let total = term.total();
                    for (mu_i, mu_o) in
                        [(1.0, 1.0), (0.2, 1.0), (0.2, 0.2), (0.6, 0.35), (0.95, 0.1)]
                    {
                        let n = 40 * N_BINS;
                        let (lo, hi) = (1e-4f64.ln(), 1e3f64.ln());
                        let du = (hi - lo) / n as f64;
                        let got: f64 = (0..n)
                            .map(|k| {
                                let x = (lo + (k as f64 + 0.5) * du).exp();
                                2.0 * std::f64::consts::PI
                                    * x
                                    * x
                                    * du
                                    * term.eval(x)
                                    * m.factor(alpha, x, mu_i, mu_o)
                            })
                            .sum();
                        eprintln!(
                            "η {eta} α {alpha} {scattering:?} ({mu_i}, {mu_o}): {:.4}",
                            got / total
                        );
                        let rel = (got / total - 1.0).abs();
                        let tol = if alpha >= 0.85 { 6e-3 } else { 0.06 };
                        worst = worst.max(if alpha >= 0.85 { rel } else { 0.0 });
                        assert!(
                            rel < tol,
                            "η {eta} α {alpha} {scattering:?} ({mu_i}, {mu_o}): {got} vs {total}"
                        );
                    }
                }
            }
        }
        eprintln!("largest deviation {worst:.2e}");
    }

    /// Light entering obliquely leaves ahead of where it entered: the first harmonic is
    /// positive at grazing incidence over the radii that carry the light, and the grazing
    /// pair's far tail is below the normal-incidence shape.
    #[test]
    fn grazing_light_moves_forward_and_stays_closer() {
        let m = ObliqueShape::new(1.0, Scattering::Multiple);
        for x in [0.5, 1.0, 2.0, 5.0] {
            let c = m.shift(0.99, x, 0.15, 1.0);
            assert!(c[0] > 0.5, "x {x}: {c:?}");
        }
        assert!(m.factor(0.99, 20.0, 0.15, 1.0) < 0.95);
        // Along the normal there is no direction to move along: no harmonic is read.
        let c = m.shift(0.99, 1.0, 1.0, 1.0);
        assert!(c.iter().all(|v| v.is_finite()));
    }

    /// The nearest node found without the logarithm is the interpolation's nearer node, on
    /// every scale of radius, both sides of every midpoint, and for 0, NaN and ∞.
    #[test]
    fn nearest_node_is_the_interpolations_nearer_node() {
        let nearer = |x: f64| {
            let (k, w) = ObliqueShape::radial_node(x);
            if w < 0.5 { k } else { k + 1 }
        };
        let mut xs: Vec<f64> = (0..4000).map(|k| 1e-4 * 1.005f64.powi(k)).collect();
        for &m in midpoints() {
            xs.extend([m * (1.0 - 1e-12), m * (1.0 + 1e-12)]);
        }
        xs.extend([0.0, -1.0, f64::NAN, f64::INFINITY]);
        for x in xs {
            assert_eq!(ObliqueShape::nearest_node(x), nearer(x), "x = {x}");
        }
    }

    /// Why the probes draw radii from the normal-incidence profile R alone and not through M
    /// (docs/oblique-incidence.md, "Sampling"): under radii drawn from 2πr R(r) the weight M
    /// of a pair has mean 1 (M integrates to 1 against the normal shape), and its second
    /// moment E[M²]/E[M]², the factor by which M's variation multiplies that part of the
    /// variance, is at most 1.05 at the median of 96 pairs (η 1 and 1.3, albedos 0.5, 0.9 and
    /// 0.99, cosines 0.1 to 1 on both sides) and below 2 at the worst (light at 84° seen along
    /// the normal): a radius drawn through M exactly could remove no more than that.
    /// Integrated on 4000 steps in ln x from e⁻⁵ to e⁴ mean free paths; prints each pair.
    #[test]
    fn radii_drawn_by_the_normal_shape_suit_every_pair() {
        use crate::profile::RadialProfile;
        let mut excess = Vec::new();
        for eta in [1.0, 1.3] {
            let shape = ObliqueShape::new(eta, Scattering::Multiple);
            for alpha in [0.5, 0.9, 0.99] {
                let term = TabulatedTerm::new(1.0, alpha, eta, false, true);
                for mu_i in [0.1, 0.2, 0.5, 1.0] {
                    for mu_o in [0.1, 0.2, 0.5, 1.0] {
                        let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
                        let n = 4000;
                        for k in 0..n {
                            let x = (-5.0 + 9.0 * (k as f64 + 0.5) / n as f64).exp();
                            // 2πx R(x) dx with dx = x d(ln x), 2π dropped.
                            let w = x * x * term.eval(x);
                            let m = shape.factor(alpha, x, mu_i, mu_o);
                            (s0, s1, s2) = (s0 + w, s1 + w * m, s2 + w * m * m);
                        }
                        let (mean, second) = (s1 / s0, s2 / s0);
                        let pair = format!("η {eta} α {alpha} μ {mu_i} {mu_o}");
                        assert!((mean - 1.0).abs() < 0.01, "{pair}: E[M] {mean}");
                        eprintln!(
                            "{pair}: E[M] {mean:.4}, E[M²]/E[M]² {:.3}",
                            second / mean.powi(2)
                        );
                        excess.push(second / mean.powi(2));
                    }
                }
            }
        }
        excess.sort_by(f64::total_cmp);
        let (median, worst) = (excess[excess.len() / 2], excess[excess.len() - 1]);
        eprintln!("E[M²]/E[M]²: median {median:.3}, largest {worst:.3}");
        assert!(
            median < 1.05 && worst < 2.0,
            "median {median}, largest {worst}"
        );
    }

    /// The interval found from the uniform spacing is the one a search from the first node
    /// finds, on every scale and both sides of every node.
    #[test]
    fn radial_position_is_the_searched_interval() {
        let n = ln_nodes();
        let searched = |l: f64| {
            let mut i = 0;
            while i + 2 < N_RADII && l >= n[i + 1] {
                i += 1;
            }
            i
        };
        let mut ls: Vec<f64> = (0..6000).map(|k| -12.0 + 0.004 * k as f64).collect();
        for &v in n.iter() {
            ls.extend([v, v - 1e-13, v + 1e-13, v.next_up(), v.next_down()]);
        }
        for l in ls {
            if l > n[0] && l < n[N_RADII - 1] {
                let (i, w) = radial_position(l);
                assert_eq!(i, searched(l), "ln x = {l}");
                assert!((0.0..=1.0).contains(&w), "ln x = {l}: {w}");
            }
        }
    }

    #[test]
    fn radial_position_brackets_every_radius() {
        let n = ln_nodes();
        for b in 0..N_RADII - 1 {
            let mid = 0.5 * (n[b] + n[b + 1]);
            let (i, w) = radial_position(mid);
            assert_eq!(i, b);
            assert!((w - 0.5).abs() < 1e-12);
        }
        assert_eq!(radial_position(f64::NEG_INFINITY), (0, 0.0));
        assert_eq!(radial_position(1e3), (N_RADII - 2, 1.0));
    }
}
