//! Randomised low-discrepancy points in the unit disk and on a segment, for the averaging
//! estimators. No allocation: a point set is a random shift, and point `k` is computed on
//! demand.
//!
//! * Unit square: the R2 sequence (Roberts 2018, "The unreasonable effectiveness of
//!   quasirandom sequences"; key Rob18): the Kronecker sequence `frac(k·α)` with
//!   `α = (1/ρ, 1/ρ²)`, ρ the plastic number (the real root of `x³ = x + 1`). Unlike a rank-1
//!   lattice it is extensible (good for every N, and points can be appended, which the
//!   replicate-based error control relies on).
//! * Segment: the golden-ratio Kronecker sequence `frac(k/φ)`.
//! * Randomisation: a Cranley–Patterson rotation (CP76): the whole set is shifted by one
//!   uniform vector, modulo 1, drawn from the caller's [`UniformSource`]. Each point is then
//!   exactly uniform, so averages are unbiased, and independent shifts give independent
//!   replicates for error estimation.
//! * Disk: Shirley & Chiu's area-preserving concentric map (SC97), which keeps the square's
//!   stratification; an ellipse is the disk with its axes scaled ([`crate::PlanarEllipse`]).
//! * Antithetic pairs: point `2j + 1` is the reflection of point `2j` through the centre
//!   (`−u` in the disk, `1 − t` on the segment). The regions are centrally symmetric about the
//!   chord midpoint, so with an even number of points the average of a *linear* field is
//!   exact (its value at the centre), and smooth fields lose their first-order error. Each
//!   point on its own is still exactly uniform.
//!
//! The arithmetic is 64-bit fixed point (`k·α` wraps modulo 2⁶⁴), so point `k` is exact for
//! every `k` and costs one multiply-add per dimension.

use std::f64::consts::FRAC_PI_4;

use glam::DVec2;

use crate::random::UniformSource;

/// 1/ρ (ρ = plastic number) in 0.64 fixed point.
const R2_ALPHA_1: u64 = 0xc13f_a9a9_02a6_328f;
/// 1/ρ² in 0.64 fixed point.
const R2_ALPHA_2: u64 = 0x91e1_0da5_c79e_7b1c;
/// 1/φ (φ = golden ratio) in 0.64 fixed point.
const GOLDEN_ALPHA: u64 = 0x9e37_79b9_7f4a_7c15;

/// A 0.64 fixed-point fraction as an `f64` in `[0, 1)` (53 significant bits).
#[inline]
fn to_unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A uniform in `[0, 1)` as a 0.64 fixed-point shift.
#[inline]
fn shift_from<U: UniformSource + ?Sized>(rng: &mut U) -> u64 {
    let u = rng.next_f64();
    debug_assert!((0.0..1.0).contains(&u), "UniformSource gave {u}");
    // Out-of-range values from a broken source are folded into [0, 1) rather than trusted.
    let u = if (0.0..1.0).contains(&u) { u } else { 0.0 };
    (u * 18_446_744_073_709_551_616.0) as u64
}

/// A set of sample points, indexed from 0, that an estimator can extend on demand.
pub trait PointSet: Sized {
    /// One point of the set.
    type Point: Copy;
    /// A new randomly shifted set (draws its shift from `rng`).
    fn new<U: UniformSource + ?Sized>(rng: &mut U) -> Self;
    /// Point `k` of the set.
    fn point(&self, k: u32) -> Self::Point;

    /// Points `k` and `k + 1`, for sets whose points come in pairs that share their work
    /// (antithetic pairs, `k` even). The same values as two calls of [`PointSet::point`].
    #[inline]
    fn point_pair(&self, k: u32) -> [Self::Point; 2] {
        [self.point(k), self.point(k + 1)]
    }
}

/// Randomly shifted R2 points mapped to the unit disk by the concentric map, in antithetic
/// pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DiskPoints {
    shift: [u64; 2],
}

impl DiskPoints {
    /// Point `k` of the shifted R2 sequence in the unit square `[0, 1)²`.
    #[inline]
    pub fn unit_square(&self, k: u32) -> [f64; 2] {
        let k = k as u64;
        [
            to_unit(self.shift[0].wrapping_add(k.wrapping_mul(R2_ALPHA_1))),
            to_unit(self.shift[1].wrapping_add(k.wrapping_mul(R2_ALPHA_2))),
        ]
    }
}

impl PointSet for DiskPoints {
    type Point = DVec2;
    fn new<U: UniformSource + ?Sized>(rng: &mut U) -> Self {
        Self {
            shift: [shift_from(rng), shift_from(rng)],
        }
    }
    /// Point `k`: the concentric map of square point `k/2`, reflected through the centre for
    /// odd `k` (antithetic pairs).
    #[inline]
    fn point(&self, k: u32) -> DVec2 {
        let u = concentric_disk(self.unit_square(k >> 1));
        if k & 1 == 0 { u } else { -u }
    }
    /// One concentric map for both points of an antithetic pair.
    #[inline]
    fn point_pair(&self, k: u32) -> [DVec2; 2] {
        if k & 1 == 0 {
            let u = concentric_disk(self.unit_square(k >> 1));
            [u, -u]
        } else {
            [self.point(k), self.point(k + 1)]
        }
    }
}

/// Randomly shifted golden-ratio points on `[0, 1]`, in antithetic pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SegmentPoints {
    shift: u64,
}

impl PointSet for SegmentPoints {
    type Point = f64;
    fn new<U: UniformSource + ?Sized>(rng: &mut U) -> Self {
        Self {
            shift: shift_from(rng),
        }
    }
    /// Point `k`: the shifted golden-ratio point `k/2`, reflected (`1 − t`) for odd `k`
    /// (antithetic pairs). In `[0, 1]`.
    #[inline]
    fn point(&self, k: u32) -> f64 {
        let t = to_unit(
            self.shift
                .wrapping_add(((k >> 1) as u64).wrapping_mul(GOLDEN_ALPHA)),
        );
        if k & 1 == 0 { t } else { 1.0 - t }
    }
}

/// Shirley & Chiu's concentric map (SC97) from `[0, 1)²` to the unit disk: area-preserving
/// (uniform in, uniform out) and continuous, so stratification of the square carries over.
/// Square rings `max(|x|, |y|) = r` (after mapping to `[-1, 1]²`) go to circles of radius r.
#[inline]
pub fn concentric_disk(u: [f64; 2]) -> DVec2 {
    let x = 2.0 * u[0] - 1.0;
    let y = 2.0 * u[1] - 1.0;
    if x == 0.0 && y == 0.0 {
        return DVec2::ZERO;
    }
    // θ = (π/4)(y/x), or π/2 − (π/4)(x/y), whose sine and cosine are the cosine and sine of
    // (π/4)(x/y): both within [−π/4, π/4].
    if x.abs() > y.abs() {
        let (s, c) = sin_cos_eighth(FRAC_PI_4 * (y / x));
        DVec2::new(x * c, x * s)
    } else {
        let (s, c) = sin_cos_eighth(FRAC_PI_4 * (x / y));
        DVec2::new(y * s, y * c)
    }
}

/// `(sin x, cos x)` for |x| ≤ π/4, by their Taylor series to x¹⁵ and x¹⁶ (the first omitted
/// terms are below 5e-17 there), evaluated by Horner's rule in x²: within 2e-16 of the library
/// functions, at a fraction of their cost (no range reduction). Outside that range the
/// series is inaccurate; use [`sin_cos_turn`] or `f64::sin_cos`.
#[inline]
pub fn sin_cos_eighth(x: f64) -> (f64, f64) {
    // sin x = x(1 − z/(2·3)(1 − z/(4·5)(1 − …))) and cos x = 1 − z/(1·2)(1 − z/(3·4)(1 − …)),
    // z = x², from the innermost factor out.
    const SIN: [f64; 7] = [
        1.0 / 210.0,
        1.0 / 156.0,
        1.0 / 110.0,
        1.0 / 72.0,
        1.0 / 42.0,
        1.0 / 20.0,
        1.0 / 6.0,
    ];
    const COS: [f64; 8] = [
        1.0 / 240.0,
        1.0 / 182.0,
        1.0 / 132.0,
        1.0 / 90.0,
        1.0 / 56.0,
        1.0 / 30.0,
        1.0 / 12.0,
        1.0 / 2.0,
    ];
    let z = x * x;
    let s = SIN.iter().fold(1.0, |acc, &k| 1.0 - z * k * acc);
    let c = COS.iter().fold(1.0, |acc, &k| 1.0 - z * k * acc);
    (x * s, c)
}

/// `(sin 2πu, cos 2πu)` for any finite `u` (an azimuth given as a fraction of a turn): the
/// nearest quarter turn is taken out exactly, and [`sin_cos_eighth`] does the rest.
#[inline]
pub fn sin_cos_turn(u: f64) -> (f64, f64) {
    // Adding and subtracting 1.5·2^52 rounds to an integer in two additions (`round` is a
    // library call on the baseline x86-64 target). It needs |4u| < 2^51, so that the sum
    // stays in [2^52, 2^53) where the spacing is 1; larger arguments take `round`.
    // (`pattern::fast_floor` with a correction to the nearest made the kernel's points 5 %
    // slower: a conversion to i64 and back, and a comparison, where this is two additions.)
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let t = 4.0 * u;
    let q = if t.abs() < 2_251_799_813_685_248.0 {
        (t + ROUND) - ROUND
    } else {
        t.round()
    };
    let (s, c) = sin_cos_eighth(std::f64::consts::TAU * (u - 0.25 * q));
    match (q as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;
    use bssrdf_core::chi_square::ChiSquareTest;
    use std::f64::consts::PI;

    /// Equal-area cells of the unit disk: `rings` rings of equal area × `sectors` sectors.
    fn disk_cell(p: DVec2, rings: usize, sectors: usize) -> usize {
        let r2 = p.length_squared().min(1.0 - 1e-15);
        let ring = (r2 * rings as f64) as usize;
        let phi = p.y.atan2(p.x).rem_euclid(2.0 * PI);
        let sector = ((phi / (2.0 * PI)) * sectors as f64) as usize % sectors;
        ring * sectors + sector
    }

    /// Chi-square test of uniformity at significance 1e-4 (fixed seed). Each point comes from
    /// its own independently shifted set, so points are i.i.d. uniform if and only if the
    /// shifted sequence and the concentric map are right; we cycle k so that every index
    /// class is exercised.
    #[test]
    fn disk_points_are_uniform_chi_square() {
        let (rings, sectors) = (8, 16);
        let cells = rings * sectors;
        let n = 256_000u64;
        let mut counts = vec![0u64; cells];
        let mut rng = SplitMix64::new(0x5eed);
        for i in 0..n {
            let set = DiskPoints::new(&mut rng);
            let p = set.point((i % 1000) as u32);
            assert!(p.length() <= 1.0 + 1e-12);
            counts[disk_cell(p, rings, sectors)] += 1;
        }
        let r = ChiSquareTest::SINGLE.check_uniform(&counts).unwrap();
        assert!(r.passes(), "{r}");
    }

    /// The series against the library functions: within 2e-16 over their range, and the turn
    /// version over several turns of either sign (within the rounding of the library's own
    /// argument 2πu).
    #[test]
    fn fast_sine_and_cosine_are_the_library_ones() {
        let n = 100_000;
        for k in 0..=n {
            let x = FRAC_PI_4 * (2.0 * k as f64 / n as f64 - 1.0);
            let (s, c) = sin_cos_eighth(x);
            assert!(
                (s - x.sin()).abs() <= 2e-16 && (c - x.cos()).abs() <= 2e-16,
                "{x}"
            );
        }
        for k in 0..=n {
            let u = 6.0 * (k as f64 / n as f64) - 3.0;
            let (s, c) = sin_cos_turn(u);
            // The library's own argument 2πu is rounded: half an ulp of it.
            let (ls, lc) = (std::f64::consts::TAU * u).sin_cos();
            let tol = 2e-16 * (1.0 + std::f64::consts::TAU * u.abs());
            assert!((s - ls).abs() <= tol && (c - lc).abs() <= tol, "{u}");
        }
        assert_eq!(sin_cos_turn(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turn(0.25), (1.0, -0.0));
        // Halfway between quarter turns, and arguments near and past 2^51 quarter turns
        // (whole quarter turns there: the exact values).
        for u in [0.125, 0.375, -0.625] {
            let (s, c) = sin_cos_turn(u);
            let (ls, lc) = (std::f64::consts::TAU * u).sin_cos();
            assert!((s - ls).abs() <= 1e-15 && (c - lc).abs() <= 1e-15, "{u}");
        }
        let cases: [(f64, (f64, f64)); 5] = [
            (2f64.powi(48) + 0.25, (1.0, 0.0)),
            (2f64.powi(49) + 0.25, (1.0, 0.0)),
            (2f64.powi(49) + 0.5, (0.0, -1.0)),
            (2f64.powi(50) + 0.75, (-1.0, 0.0)),
            (-(2f64.powi(52)), (0.0, 1.0)),
        ];
        for (u, want) in cases {
            let (s, c) = sin_cos_turn(u);
            assert!(s == want.0 && c == want.1, "{u}: {s} {c}");
        }
    }

    /// A pair is the two points, bit for bit, from either parity of k.
    #[test]
    fn point_pairs_are_the_points() {
        let mut rng = SplitMix64::new(23);
        for _ in 0..50 {
            let set = DiskPoints::new(&mut rng);
            for k in 0..64 {
                assert_eq!(
                    set.point_pair(k),
                    [set.point(k), set.point(k + 1)],
                    "k = {k}"
                );
            }
        }
    }

    /// The same test for the points of one set (k = 0..N with a single shift): the
    /// low-discrepancy set must be far *more* even than random points, so its mean statistic
    /// over many shifts must be well below the i.i.d. expectation (dof). A broken stratification
    /// (e.g. k ignored, or α rational with small denominator) fails this.
    #[test]
    fn one_shifted_set_is_more_even_than_random() {
        let (rings, sectors) = (4, 8);
        let cells = rings * sectors;
        let n = 1024u32;
        let mut rng = SplitMix64::new(17);
        let reps = 50;
        let mut mean_stat = 0.0;
        for _ in 0..reps {
            let set = DiskPoints::new(&mut rng);
            let mut counts = vec![0u64; cells];
            for k in 0..n {
                counts[disk_cell(set.point(k), rings, sectors)] += 1;
            }
            let r = ChiSquareTest::SINGLE.check_uniform(&counts).unwrap();
            mean_stat += r.statistic / reps as f64;
        }
        // i.i.d. points would give E[stat] = dof = 31.
        assert!(
            mean_stat < (cells - 1) as f64 / 4.0,
            "mean chi2 {mean_stat}"
        );
    }

    /// Ellipse points (disk scaled by (a, b)): chi-square over the cells of a grid on the
    /// bounding box, with expected counts from an independent fine-grid area quadrature of
    /// each cell's intersection with the ellipse. Significance 1e-4, fixed seed.
    #[test]
    fn ellipse_points_are_uniform_chi_square() {
        let (a, b) = (2.0, 0.7);
        let g = 8usize; // 8×8 cells over [-a, a]×[-b, b]
        let cell_of = |x: f64, y: f64| -> usize {
            let i = (((x + a) / (2.0 * a)) * g as f64).clamp(0.0, g as f64 - 1.0) as usize;
            let j = (((y + b) / (2.0 * b)) * g as f64).clamp(0.0, g as f64 - 1.0) as usize;
            j * g + i
        };
        // Independent quadrature: fraction of a 1600×1600 midpoint grid inside the ellipse.
        let q = 1600usize;
        let mut area = vec![0u64; g * g];
        let mut inside = 0u64;
        for j in 0..q {
            for i in 0..q {
                let x = -a + (i as f64 + 0.5) * 2.0 * a / q as f64;
                let y = -b + (j as f64 + 0.5) * 2.0 * b / q as f64;
                if (x / a).powi(2) + (y / b).powi(2) <= 1.0 {
                    area[cell_of(x, y)] += 1;
                    inside += 1;
                }
            }
        }
        let n = 200_000u64;
        let mut counts = vec![0u64; g * g];
        let mut rng = SplitMix64::new(99);
        for i in 0..n {
            let u = DiskPoints::new(&mut rng).point((i % 333) as u32);
            counts[cell_of(a * u.x, b * u.y)] += 1;
        }
        // Corner cells expecting fewer than 5 points are pooled by the helper.
        let expected: Vec<f64> = area
            .iter()
            .map(|&a| n as f64 * a as f64 / inside as f64)
            .collect();
        let r = ChiSquareTest::SINGLE.check(&counts, &expected).unwrap();
        assert!(r.passes(), "{r}");
    }

    /// Segment points: chi-square over 50 equal bins, i.i.d. across shifts, significance 1e-4.
    #[test]
    fn segment_points_are_uniform_chi_square() {
        let bins = 50;
        let n = 100_000u64;
        let mut counts = vec![0u64; bins];
        let mut rng = SplitMix64::new(3);
        for i in 0..n {
            let t = SegmentPoints::new(&mut rng).point((i % 77) as u32);
            assert!((0.0..=1.0).contains(&t));
            counts[((t * bins as f64) as usize).min(bins - 1)] += 1;
        }
        let r = ChiSquareTest::SINGLE.check_uniform(&counts).unwrap();
        assert!(r.passes(), "{r}");
    }

    #[test]
    fn antithetic_pairs_are_centrally_symmetric() {
        let mut rng = SplitMix64::new(8);
        let (d, s) = (DiskPoints::new(&mut rng), SegmentPoints::new(&mut rng));
        for j in 0..100 {
            assert_eq!(d.point(2 * j), -d.point(2 * j + 1));
            assert!((s.point(2 * j) + s.point(2 * j + 1) - 1.0).abs() < 1e-15);
        }
        // Consecutive pairs are different points (k/2 advances).
        assert_ne!(d.point(0), d.point(2));
    }

    #[test]
    fn concentric_map_edges_and_corners() {
        assert_eq!(concentric_disk([0.5, 0.5]), DVec2::ZERO);
        for u in [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.5]] {
            let p = concentric_disk(u);
            assert!((p.length() - 1.0).abs() < 1e-12, "{u:?} -> {p}");
        }
        // Square ring max(|x|,|y|) = 0.5 goes to the circle of radius 0.5.
        let p = concentric_disk([0.75, 0.6]);
        assert!((p.length() - 0.5).abs() < 1e-12);
    }
}
