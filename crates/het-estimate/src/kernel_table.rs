//! The depth-integrated averaging kernel W₂, tabulated once per boundary condition
//! (docs/kernel.md#the-table).
//!
//! In transport units (lengths × σt', [`crate::green`]) the kernel at a surface point p for the
//! pair (x_i, x_o) is
//!
//! `W₂(p) = ∫₀^∞ G(s_i, (p, ζ)) · G((p, ζ), s_o) dζ`,
//!
//! s_i, s_o the sources one transport mean free path below x_i and x_o. It depends on p only
//! through the horizontal distances ρ_i = |p − x_i| and ρ_o = |p − x_o|, and on the material
//! through κ = σtr/σt' and the boundary coefficient A. So one table per A over (κ, ρ_i, ρ_o)
//! serves every chord length and every coefficient value. The table stores
//! `h = ln W̃₂` with `W̃₂ = e^{κ(ρ_i + ρ_o)}·W₂·(4πD)²` (the exponential factor is put back in
//! closed form by the caller), which is smooth in all three arguments.
//!
//! # Grid
//! * ρ: [`RHO_NODES`] nodes uniform in x = ρ/(ρ + [`RHO_SCALE`]) ∈ [0, 1) (spacing about 0.06
//!   near 0, reaching ρ = 252 at the last node); beyond the last node h continues along each
//!   axis that is out of range with the slope in ln ρ of the last cell
//!   ([`KappaSlice::log_weight`]: the far field is a power law in ρ times the exact e^{−κρ}
//!   factor, which holding h constant would over-weight without bound). The ρ = 0 node is
//!   evaluated at [`RHO_FLOOR`], because W₂ diverges logarithmically where p is right above a
//!   source.
//! * κ: [`KAPPA_NODES`] nodes uniform on [0, √3].
//! * Depth: composite 4-point Gauss–Legendre on panels one e-fold wide in ln|ζ − 1|, from 1e-5
//!   to 1 above the sources' depth and to 1e4 below it (132 nodes shared by all entries, so
//!   the table is a product of two small matrices per κ).
//!
//! Lookups are trilinear in (κ, x_i, x_o): eight reads and no transcendental function.

use std::sync::{Arc, Mutex, Weak};

use crate::green::scaled_green;

/// Nodes along each distance axis.
pub const RHO_NODES: usize = 64;
/// The scale of the distance map x = ρ/(ρ + RHO_SCALE) (transport mean free paths).
pub const RHO_SCALE: f64 = 4.0;
/// The distance at which the ρ = 0 node is evaluated (W₂ is log-singular at 0).
pub const RHO_FLOOR: f64 = 0.015;
/// Nodes along κ = σtr/σt' ∈ [0, √3].
pub const KAPPA_NODES: usize = 16;
/// The largest κ: √3 (a pure absorber, σs' = 0).
pub const KAPPA_MAX: f64 = 1.732_050_807_568_877_2;

/// 4-point Gauss–Legendre nodes and weights on [−1, 1].
const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// The depth nodes (ζ, weight) of the table's quadrature (see the module docs).
pub fn depth_nodes() -> Vec<(f64, f64)> {
    let mut nodes = Vec::with_capacity(132);
    let ln_min = (1e-5f64).ln();
    // Above the sources (ζ = 1 − t, t ∈ [1e-5, 1]) and below them (ζ = 1 + t, t ∈ [1e-5, 1e4]).
    for (sign, ln_max) in [(-1.0, 0.0), (1.0, (1e4f64).ln())] {
        let panels = (ln_max - ln_min).ceil() as usize;
        let width = (ln_max - ln_min) / panels as f64;
        for k in 0..panels {
            let mid = ln_min + (k as f64 + 0.5) * width;
            for (x, w) in GL4 {
                let t = (mid + 0.5 * width * x).exp();
                nodes.push((1.0 + sign * t, w * 0.5 * width * t));
            }
        }
    }
    nodes
}

/// The distance of node `k` of a ρ axis.
pub fn rho_node(k: usize) -> f64 {
    let x = k as f64 / RHO_NODES as f64;
    (RHO_SCALE * x / (1.0 - x)).max(RHO_FLOOR)
}

/// The κ of node `j`.
pub fn kappa_node(j: usize) -> f64 {
    KAPPA_MAX * j as f64 / (KAPPA_NODES - 1) as f64
}

/// The tables alive in the process ([`KernelTable::shared`]), by weak reference.
static TABLES: Mutex<Vec<Weak<KernelTable>>> = Mutex::new(Vec::new());

/// `h = ln W̃₂(ρ_i, ρ_o; κ, A)` for one boundary coefficient A (see the module docs).
pub struct KernelTable {
    a: f64,
    /// `h[j][i·RHO_NODES + o]` for κ node j and distance nodes i, o.
    h: Box<[Slice; KAPPA_NODES]>,
}

impl std::fmt::Debug for KernelTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KernelTable").field("a", &self.a).finish()
    }
}

/// A table is determined by its A.
impl PartialEq for KernelTable {
    fn eq(&self, o: &Self) -> bool {
        self.a == o.a
    }
}

impl KernelTable {
    /// Builds the table for boundary coefficient `a` ≥ 1 (a few ms in release builds).
    pub fn build(a: f64) -> Self {
        let zb = 2.0 * a / 3.0;
        let depth = depth_nodes();
        let n = RHO_NODES;
        let mut h: Box<[Slice; KAPPA_NODES]> = vec![[0f64; RHO_NODES * RHO_NODES]; KAPPA_NODES]
            .into_boxed_slice()
            .try_into()
            .expect("KAPPA_NODES slices");
        let mut g = vec![0f64; n * depth.len()];
        for j in 0..KAPPA_NODES {
            let kappa = kappa_node(j);
            for i in 0..n {
                let rho = rho_node(i);
                for (z, &(zeta, _)) in depth.iter().enumerate() {
                    g[i * depth.len() + z] = scaled_green(rho, zeta, kappa, zb);
                }
            }
            for i in 0..n {
                for o in i..n {
                    let (gi, go) = (&g[i * depth.len()..], &g[o * depth.len()..]);
                    let w2: f64 = depth
                        .iter()
                        .enumerate()
                        .map(|(z, &(_, w))| w * (gi[z] * go[z]))
                        .sum();
                    let v = w2.ln();
                    h[j][i * n + o] = v;
                    h[j][o * n + i] = v;
                }
            }
        }
        Self { a, h }
    }

    /// The table for boundary coefficient `a`, shared with every other live holder of the
    /// same A (one per distinct η among the prepared materials; 512 KiB each: f64, which
    /// reads faster than f32 and its conversions). The caller owns it: the table is freed when
    /// the last holder (a `PreparedEstimator`) is dropped, so preparing materials for any
    /// number of distinct η (an artist dragging a slider) keeps only the live ones in memory
    /// (`examples/kernel_memory.rs` prints the resident set across 1,000 η). The registry
    /// holds weak references only.
    pub fn shared(a: f64) -> Arc<KernelTable> {
        let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
        tables.retain(|t| t.strong_count() > 0);
        if let Some(t) = tables.iter().find_map(|t| t.upgrade().filter(|t| t.a == a)) {
            return t;
        }
        let t = Arc::new(KernelTable::build(a));
        tables.push(Arc::downgrade(&t));
        t
    }

    /// How many tables are alive (held by some prepared estimator) in this process.
    pub fn live_tables() -> usize {
        let tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
        tables.iter().filter(|t| t.strong_count() > 0).count()
    }

    /// The boundary coefficient A of this table.
    pub fn boundary_coefficient(&self) -> f64 {
        self.a
    }

    /// `h = ln W̃₂` at distances `rho_i`, `rho_o` ≥ 0 and `kappa` ∈ [0, √3] (transport units;
    /// out-of-range arguments are clamped to the grid). Finite for every input, NaN included.
    #[inline]
    pub fn log_weight(&self, rho_i: f64, rho_o: f64, kappa: f64) -> f64 {
        self.at_kappa(kappa).log_weight(rho_i, rho_o)
    }

    /// The table at one κ (clamped to [0, √3]; NaN reads as √3, since `f64::min` returns the
    /// number when one side is NaN): the two κ slices around it
    /// and the blend between them, found once for the many lookups of one weighted average.
    #[inline]
    pub fn at_kappa(&self, kappa: f64) -> KappaSlice<'_> {
        let top = (KAPPA_NODES - 1) as f64;
        let f = (kappa / KAPPA_MAX * top).min(top).max(0.0);
        let j = (f as usize).min(KAPPA_NODES - 2);
        KappaSlice {
            lo: &self.h[j],
            hi: &self.h[j + 1],
            t: f - j as f64,
        }
    }
}

/// The table at one κ ([`KernelTable::at_kappa`]): bilinear in the two distances on each of
/// the two κ slices around it, linear between them.
#[derive(Clone, Copy)]
pub struct KappaSlice<'a> {
    lo: &'a Slice,
    hi: &'a Slice,
    t: f64,
}

impl std::fmt::Debug for KappaSlice<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KappaSlice").field("t", &self.t).finish()
    }
}

impl KappaSlice<'_> {
    /// `h = ln W̃₂` at distances `rho_i`, `rho_o` ≥ 0 (transport units), as
    /// [`KernelTable::log_weight`] at this slice's κ.
    #[inline]
    pub fn log_weight(&self, rho_i: f64, rho_o: f64) -> f64 {
        let h = self.on_grid(rho_i, rho_o);
        let last = rho_node(RHO_NODES - 1);
        if rho_i > last || rho_o > last {
            self.extrapolate(h, rho_i, rho_o)
        } else {
            h
        }
    }

    /// Beyond the last node: continue with the log-log slope of the last cell along each
    /// axis that is out of range (the far field is a power law in ρ times the exact
    /// exponential; holding h constant would over-weight it without bound).
    #[cold]
    fn extrapolate(&self, mut h: f64, rho_i: f64, rho_o: f64) -> f64 {
        let n = RHO_NODES;
        let (last, prev) = (rho_node(n - 1), rho_node(n - 2));
        let step = last.ln() - prev.ln();
        let (ci, co) = (rho_i.min(last), rho_o.min(last));
        if rho_i > last {
            let slope = (self.on_grid(last, co) - self.on_grid(prev, co)) / step;
            h += slope * (rho_i.min(1e300).ln() - last.ln());
        }
        if rho_o > last {
            let slope = (self.on_grid(ci, last) - self.on_grid(ci, prev)) / step;
            h += slope * (rho_o.min(1e300).ln() - last.ln());
        }
        h
    }

    /// Trilinear interpolation of the grid, clamped to it.
    #[inline]
    fn on_grid(&self, rho_i: f64, rho_o: f64) -> f64 {
        const N: usize = RHO_NODES;
        // 1 − s/(ρ + s) rather than ρ/(ρ + s): ρ = ∞ maps to 1, not NaN.
        let cell = |rho: f64| {
            let f = ((1.0 - RHO_SCALE / (rho + RHO_SCALE)) * N as f64)
                .min((N - 1) as f64)
                .max(0.0);
            let k = (f as usize).min(N - 2);
            (k, f - k as f64)
        };
        let (i, ti) = cell(rho_i);
        let (o, to) = cell(rho_o);
        // The cell's four corners are `base`, `base + 1`, `base + N` and `base + N + 1`,
        // all inside the slice since i, o ≤ N − 2.
        let base = i * N + o;
        let bilinear = |s: &Slice| {
            let c = &s[base..base + N + 2];
            let (v00, v01) = (c[0], c[1]);
            let (v10, v11) = (c[N], c[N + 1]);
            let lo = v00 + to * (v01 - v00);
            let hi = v10 + to * (v11 - v10);
            lo + ti * (hi - lo)
        };
        let (a, b) = (bilinear(self.lo), bilinear(self.hi));
        a + self.t * (b - a)
    }
}

/// One κ slice of the table: `h[i·RHO_NODES + o]` for distance nodes i, o.
type Slice = [f64; RHO_NODES * RHO_NODES];

#[cfg(test)]
mod tests {
    use super::*;

    /// W̃₂ by an independent rule: adaptive Simpson in ζ on [0, 1] and on [1, ∞) mapped by
    /// ζ = 1 + u/(1 − u), straight from the closed-form Green's function.
    fn direct(rho_i: f64, rho_o: f64, kappa: f64, zb: f64) -> f64 {
        /// An interval of the recursion: [a, b], f at its ends and midpoint, and its Simpson
        /// estimate.
        struct Panel {
            a: f64,
            b: f64,
            fa: f64,
            fm: f64,
            fb: f64,
            whole: f64,
        }
        /// One step of the textbook recursion: both halves of `p`, refined further unless
        /// they agree with `p`'s estimate (or `depth` is spent).
        fn simpson(f: &dyn Fn(f64) -> f64, p: Panel, depth: u32) -> f64 {
            let Panel {
                a,
                b,
                fa,
                fm,
                fb,
                whole,
            } = p;
            let m = 0.5 * (a + b);
            let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
            let (flm, frm) = (f(lm), f(rm));
            let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
            let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
            if depth == 0 || (left + right - whole).abs() <= 1e-10 * (left + right).abs() {
                left + right + (left + right - whole) / 15.0
            } else {
                let left_half = Panel {
                    a,
                    b: m,
                    fa,
                    fm: flm,
                    fb: fm,
                    whole: left,
                };
                let right_half = Panel {
                    a: m,
                    b,
                    fa: fm,
                    fm: frm,
                    fb,
                    whole: right,
                };
                simpson(f, left_half, depth - 1) + simpson(f, right_half, depth - 1)
            }
        }
        let integrate = |f: &dyn Fn(f64) -> f64, a: f64, b: f64| {
            let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
            let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
            simpson(
                f,
                Panel {
                    a,
                    b,
                    fa,
                    fm,
                    fb,
                    whole,
                },
                40,
            )
        };
        let w =
            |zeta: f64| scaled_green(rho_i, zeta, kappa, zb) * scaled_green(rho_o, zeta, kappa, zb);
        let upper = |u: f64| {
            if u >= 1.0 {
                0.0
            } else {
                let s = 1.0 - u;
                w(1.0 + u / s) / (s * s)
            }
        };
        integrate(&w, 0.0, 1.0) + integrate(&upper, 0.0, 1.0)
    }

    /// The table against direct quadrature of the closed-form Green's functions, off the
    /// grid: within 3 % of W₂ (0.03 in h) for distances from 0.2 to 60 mean free paths,
    /// κ over its range and A for η = 1 and η ≈ 1.5.
    #[test]
    fn table_matches_direct_quadrature() {
        for a in [1.0, 3.95474] {
            let t = KernelTable::build(a);
            let zb = 2.0 * a / 3.0;
            for &(ri, ro) in &[
                (0.2, 0.2),
                (0.37, 2.9),
                (1.3, 1.1),
                (4.4, 9.7),
                (17.0, 3.3),
                (60.0, 55.0),
            ] {
                for kappa in [0.0, 0.13, 0.61, 1.5] {
                    let want = direct(ri, ro, kappa, zb).ln();
                    let got = t.log_weight(ri, ro, kappa);
                    assert!(
                        (got - want).abs() < 0.03,
                        "A={a} ρ=({ri},{ro}) κ={kappa}: {got} vs {want}"
                    );
                }
            }
        }
    }

    /// Tables are owned by their holders: one distinct A at a time stays one table, however
    /// many A are prepared in turn, and a dropped table is rebuilt on demand.
    #[test]
    fn tables_are_freed_with_their_last_holder() {
        // A values no other test uses, so that parallel tests do not hold them.
        let a0 = 7.123_456;
        let held = KernelTable::shared(a0);
        for k in 1..=5 {
            let t = KernelTable::shared(a0 + k as f64 * 1e-3);
            assert_eq!(Arc::strong_count(&t), 1, "only the caller holds it");
        }
        let again = KernelTable::shared(a0);
        assert!(Arc::ptr_eq(&held, &again));
        assert_eq!(Arc::strong_count(&held), 2);
        drop((held, again));
        let weak = Arc::downgrade(&KernelTable::shared(a0));
        assert_eq!(weak.strong_count(), 0, "freed with its last holder");
    }

    #[test]
    fn table_is_symmetric_and_finite() {
        let t = KernelTable::shared(1.0);
        assert!(Arc::ptr_eq(&t, &KernelTable::shared(1.0)));
        for &(ri, ro, k) in &[
            (0.3, 7.0, 0.2),
            (0.0, 0.0, 0.0),
            (1e9, 0.0, 1.7),
            (f64::INFINITY, 2.0, 9.0),
            (f64::NAN, 1.0, f64::NAN),
        ] {
            let (a, b) = (t.log_weight(ri, ro, k), t.log_weight(ro, ri, k));
            assert!(a.is_finite() && b.is_finite());
            if ri.is_finite() && ro.is_finite() {
                assert!((a - b).abs() < 1e-6);
            }
        }
        assert!(t.h.iter().flatten().all(|v| v.is_finite()));
        // A NaN κ reads as the clamp's top, √3 (as documented on `at_kappa`).
        for (ri, ro) in [(0.3, 7.0), (2.0, 2.0)] {
            assert_eq!(
                t.log_weight(ri, ro, f64::NAN),
                t.log_weight(ri, ro, KAPPA_MAX)
            );
        }
    }
}
