//! Piecewise-constant distributions over `[0, 1)` and `[0, 1)²`, sampled by inverting their
//! cumulative distribution (pbrt3 §13.6.7 and pbrt-v4 §A.5.6, `PiecewiseConstant1D` and
//! `PiecewiseConstant2D`): the environment map's importance sampling
//! ([`crate::light::EnvironmentMap`]).
//!
//! A 1D distribution of `n` non-negative values `f_k` has the density
//! `p(x) = f_k / (Σ f / n)` on `[k/n, (k+1)/n)`. A 2D one over an `nu × nv` grid (row-major, row
//! `j` spans `v ∈ [j/nv, (j+1)/nv)`) samples `v` from the marginal of the row sums, then `u` from
//! that row's conditional; its density is `p(u, v) = f(u, v) / (Σ f / (nu·nv))`. A function that
//! is zero everywhere gives the uniform distribution (so that sampling never divides by zero).

/// A piecewise-constant density on `[0, 1)`.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseConstant1D {
    /// The (non-negative, finite) values, or all 1 when they summed to 0.
    func: Vec<f64>,
    /// `cdf[k]` = the probability of `[0, k/n)`; `cdf[n] = 1`.
    cdf: Vec<f64>,
    /// `∫₀¹ f = Σ f / n` of the given values (0 for an all-zero function).
    integral: f64,
}

impl PiecewiseConstant1D {
    /// The distribution of `func` (at least one value; negative or non-finite values count as
    /// 0, which callers rule out beforehand).
    pub fn new(func: &[f64]) -> Self {
        assert!(!func.is_empty(), "a distribution needs at least one value");
        let n = func.len();
        let mut func: Vec<f64> = func
            .iter()
            .map(|&f| if f.is_finite() && f > 0.0 { f } else { 0.0 })
            .collect();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut sum = 0.0;
        for &f in &func {
            sum += f / n as f64;
            cdf.push(sum);
        }
        let integral = sum;
        if integral > 0.0 {
            for c in &mut cdf[1..] {
                *c /= integral;
            }
        } else {
            func.iter_mut().for_each(|f| *f = 1.0);
            for (k, c) in cdf.iter_mut().enumerate() {
                *c = k as f64 / n as f64;
            }
        }
        cdf[n] = 1.0;
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Always false (a distribution has at least one piece).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `∫₀¹ f` of the values given (0 when they were all zero).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The normaliser of the density: `∫₀¹ f`, or 1 for an all-zero function (sampled
    /// uniformly).
    fn norm(&self) -> f64 {
        if self.integral > 0.0 {
            self.integral
        } else {
            1.0
        }
    }

    /// Samples `x ∈ [0, 1)` with `u ∈ [0, 1)`: `(x, p(x), piece)`. The piece is never one of
    /// zero probability.
    pub fn sample(&self, u: f64) -> (f64, f64, usize) {
        let n = self.func.len();
        // The last k with cdf[k] ≤ u, among pieces of non-zero width in the cdf.
        let k = self
            .cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1);
        // Skip empty pieces (cdf[k] == cdf[k + 1]) that u may land on at their shared edge.
        let k = (k..n).find(|&k| self.func[k] > 0.0).unwrap_or(k);
        let width = self.cdf[k + 1] - self.cdf[k];
        let du = if width > 0.0 {
            ((u - self.cdf[k]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let x = ((k as f64 + du) / n as f64).min(1.0 - f64::EPSILON / 2.0);
        (x, self.func[k] / self.norm(), k)
    }

    /// The density at `x` (0 outside `[0, 1)`).
    pub fn pdf(&self, x: f64) -> f64 {
        if !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        let n = self.func.len();
        let k = ((x * n as f64) as usize).min(n - 1);
        self.func[k] / self.norm()
    }
}

/// A piecewise-constant density on `[0, 1)²` (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseConstant2D {
    /// One distribution of `u` per row.
    conditional: Vec<PiecewiseConstant1D>,
    /// The distribution of the rows.
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// The distribution of `func`, `nu` values per row and `nv` rows (row-major).
    pub fn new(func: &[f64], nu: usize, nv: usize) -> Self {
        assert!(
            nu > 0 && nv > 0 && func.len() == nu * nv,
            "a {nu} × {nv} distribution needs {} values, got {}",
            nu * nv,
            func.len()
        );
        let conditional: Vec<PiecewiseConstant1D> = func
            .chunks_exact(nu)
            .map(PiecewiseConstant1D::new)
            .collect();
        let rows: Vec<f64> = conditional.iter().map(|c| c.integral()).collect();
        Self {
            marginal: PiecewiseConstant1D::new(&rows),
            conditional,
        }
    }

    /// `∫∫ f` over the unit square (0 when the function was zero).
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Samples `(u, v)` with the uniforms `r ∈ [0, 1)²` (`r[0]` picks the row): the point and
    /// its density.
    pub fn sample(&self, r: [f64; 2]) -> ([f64; 2], f64) {
        let (v, pv, row) = self.marginal.sample(r[0]);
        let (u, pu, _) = self.conditional[row].sample(r[1]);
        ([u, v], pu * pv)
    }

    /// The density at `(u, v)` (0 outside the unit square).
    pub fn pdf(&self, p: [f64; 2]) -> f64 {
        if !(0.0..1.0).contains(&p[1]) {
            return 0.0;
        }
        let nv = self.conditional.len();
        let row = ((p[1] * nv as f64) as usize).min(nv - 1);
        self.marginal.pdf(p[1]) * self.conditional[row].pdf(p[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use bssrdf_core::chi_square::ChiSquareTest;

    #[test]
    fn one_dimension_inverts_its_cdf() {
        let d = PiecewiseConstant1D::new(&[1.0, 0.0, 3.0, 4.0]);
        assert!((d.integral() - 2.0).abs() < 1e-15);
        // u = 0.125 lies in the first piece (probability 1/8), at its middle.
        let (x, p, k) = d.sample(1.0 / 16.0);
        assert_eq!(k, 0);
        assert!((x - 0.125).abs() < 1e-12 && (p - 0.5).abs() < 1e-12);
        // The empty piece is never returned, even at its edge.
        let (_, _, k) = d.sample(0.125);
        assert_eq!(k, 2);
        assert_eq!(d.pdf(0.3), 0.0);
        assert!((d.pdf(0.9) - 2.0).abs() < 1e-12);
        // An all-zero function is sampled uniformly.
        let z = PiecewiseConstant1D::new(&[0.0, 0.0]);
        assert_eq!(z.integral(), 0.0);
        assert_eq!(z.sample(0.75).1, 1.0);
    }

    /// Samples of a 2D distribution over its own cells against the cell probabilities its
    /// values give (f / Σ f), by χ².
    #[test]
    fn two_dimensions_sample_their_values() {
        let (nu, nv) = (7, 5);
        let func: Vec<f64> = (0..nu * nv)
            .map(|k| {
                if k % 11 == 3 {
                    0.0
                } else {
                    1.0 + (k % 4) as f64
                }
            })
            .collect();
        let d = PiecewiseConstant2D::new(&func, nu, nv);
        let total: f64 = func.iter().sum();
        let mut rng = Rng::from_keys(5, &[]);
        let n = 200_000;
        let mut counts = vec![0u64; nu * nv];
        for _ in 0..n {
            let ([u, v], p) = d.sample(rng.uniform2());
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
            let cell = (v * nv as f64) as usize * nu + (u * nu as f64) as usize;
            assert!((p - d.pdf([u, v])).abs() < 1e-12 * p);
            assert!((p - func[cell] / total * (nu * nv) as f64).abs() < 1e-9);
            counts[cell] += 1;
        }
        let expected: Vec<f64> = func.iter().map(|f| f / total * n as f64).collect();
        let (o, e): (Vec<u64>, Vec<f64>) = counts
            .iter()
            .zip(&expected)
            .filter(|(_, e)| **e > 0.0)
            .map(|(o, e)| (*o, *e))
            .unzip();
        let r = ChiSquareTest::SINGLE.check(&o, &e).unwrap();
        assert!(r.passes(), "{r}");
        assert!(
            counts.iter().zip(&func).all(|(c, f)| *f > 0.0 || *c == 0),
            "an empty cell was sampled"
        );
    }
}
