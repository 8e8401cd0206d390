//! Summed-area table of an image texture, and the prefiltered average of Eq. (3) of the paper
//! (uniform area average over the averaging ellipse) for planar-projected images.
//!
//! # Table
//! `S(i, j) = Σ_{i' < i, j' < j} (texel(i', j') − mean)` for `0 ≤ i ≤ W`, `0 ≤ j ≤ H`, per
//! channel in `f64` (Crow 1984, "Summed-area tables for texture mapping"; pbrt-v3 §10.4.3).
//! Subtracting the per-channel mean keeps the table's entries of the order of one row's
//! contrast instead of `W·H·max`, and makes a whole period integrate to zero. The texture with
//! nearest filtering is constant on each texel, so its integral `F(x, y)` over
//! `[0, x] × [0, y]` is bilinear inside each cell of the table: the integral over any
//! rectangle with real corners is exact (to rounding) from four interpolated corners. Outside
//! `[0, W] × [0, H]`, `F` is extended by the wrap mode: `repeat` adds whole periods (zero after
//! the mean is removed) and the remainder, `clamp` continues the edge rows and columns
//! linearly ([`AreaTable::rect_integral`]).
//!
//! Built once per texture ([`super::Texture::area_table`], a `OnceLock`) when a render that
//! reads region averages is prepared (`MediumField::build_area_tables`, called by
//! `PathIntegrator::new` for `sone` with prefiltered averaging), else on the first prefiltered
//! average: the scene does not know at load time which method will render it (the command
//! line may override `render.averaging`), and textures that only the path tracer, Jensen's
//! methods, the kernel or Monte Carlo averaging read never build one.
//! Memory: `(W + 1)(H + 1)` × 24 bytes, twice the decoded texture.
//!
//! # Ellipse average (derivation: `docs/physics.md#prefiltered-averages`)
//! The footprint is an ellipse in texel space, `c + X·a_u + Y·a_v`, `X² + Y² ≤ 1`. Its rows
//! are cut into horizontal strips: "mip level" `k` is the smallest band height `2^k` texel rows
//! (`k ≥ −8`) for which the ellipse's height `2h_y` spans at most [`MAX_ROWS`] (32) bands;
//! strips are those bands clipped to the ellipse (at most `MAX_ROWS + 1` of them). A level-`k`
//! band (`k ≥ 0`) is what a row of a box-filtered mip level `k` holds, but read from the
//! level-0 table, so columns keep full resolution (no horizontal blur) and one table serves
//! every level; footprints under 32 rows tall are cut finer than a texel row (`k < 0`), so
//! small footprints get as many strips as large ones. 16 strips were measured too coarse (a
//! bias of about 1 % of the contrast, 5 standard errors of 10^5 samples on a random texture);
//! 32 pass that test. Each strip is
//! replaced by the rectangle of the same height and the *same area* as the ellipse inside the
//! strip (the semicircle law gives that area in closed form), centred on the ellipse's chord
//! centre at the strip's middle (the centres are collinear), and integrated exactly through
//! the table. The average is the sum of the strips' integrals over the ellipse's area: O(1)
//! per strip, O(`MAX_ROWS`) per footprint whatever its size.
//!
//! Error (nearest filtering): the staircase `S` has the ellipse's area, so the average errs by
//! at most `(max − min)·|S Δ E| / (2|E|)` over the texels it meets. In each strip the
//! rectangle's ends are the strip means of the chord's ends, hence
//! `|S Δ E| ≤ Σ h_strip (range of x_left + range of x_right)/2 ≤ 4·h_x·2^k` (`h_x` the
//! half-width), i.e. at most `2 h_x 2^k / (π |det M|)` of the contrast: ≤ 1/(8π) ≈ 4 % for a
//! disk cut in 32 strips. For a thin ellipse the bound grows as a/b (a tilted one is cut into
//! strips across its length, each a sliver the rectangle fits poorly): about `sin 2θ·a/(16π b)`
//! at angle θ to the rows. The worst case is a texture edge lying along the boundary; over a
//! textured interior the in and out slivers of each strip largely cancel. Measured against the
//! exact mean (`tests::thin_ellipse_errors`, ellipses 20 texels long at random angles on a
//! random texture), the mean (largest) error is 0.05 % (0.21 %) of the contrast for a disk,
//! 0.09 % (0.6 %) at b/a = 0.1, 0.64 % (3.7 %) at 0.01 and 1.2 % (5.6 %) at 0.003; on a disk
//! the tests also find the average within 5 standard errors of 10^5 samples.
//!
//! Bilinear filtering is averaged as nearest: bilinear interpolation is the nearest
//! reconstruction convolved with a one-texel box, so over a region `R` the two averages differ
//! by `∫ f_N (1_R ∗ box − 1_R) / |R|`, a kernel that integrates to zero and whose absolute
//! integral is a quarter texel per unit of boundary length. The extra error is at most
//! `(max − min)·P/(8|R|)` (P the perimeter, in texels): `(max − min)/(4r)` for a disk of
//! radius `r` texels, i.e. 2.5 % of the contrast at r = 10 texels, 0.25 % at r = 100.

use super::texture_mapping::Wrap;

/// Most texel bands (mip-level rows) a footprint's height may span; the strip count is at
/// most one more (bands are aligned to the level's rows).
pub const MAX_ROWS: f64 = 32.0;

/// Finest band: `2^-8` texel rows (footprints within a texel still get [`MAX_ROWS`] strips).
const MIN_LEVEL: i32 = -8;
const MIN_BAND: f64 = 1.0 / 256.0;

/// Levels above this are not used (`2^40` rows: a footprint wider than any texture's period by
/// orders of magnitude is declined).
const MAX_LEVEL: i32 = 40;

/// The summed-area table of a texture (see the module docs).
#[derive(Clone, PartialEq)]
pub struct AreaTable {
    width: usize,
    height: usize,
    mean: [f64; 3],
    inv_w: f64,
    inv_h: f64,
    /// `(W + 1) × (H + 1)` entries, row-major.
    sat: Vec<[f64; 3]>,
}

impl std::fmt::Debug for AreaTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "AreaTable({}×{})", self.width, self.height)
    }
}

/// An ellipse in continuous texel coordinates (`x` right, `y` down; texel `(i, j)` covers
/// `[i, i+1) × [j, j+1)`): `centre + X·axis_u + Y·axis_v` for `X² + Y² ≤ 1` (conjugate
/// semi-axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexelEllipse {
    /// Centre, texels.
    pub centre: [f64; 2],
    /// First conjugate semi-axis, texels.
    pub axis_u: [f64; 2],
    /// Second conjugate semi-axis, texels.
    pub axis_v: [f64; 2],
}

impl TexelEllipse {
    /// Half its height (texel rows): `hypot(a_u.y, a_v.y)`.
    pub fn half_height(&self) -> f64 {
        self.axis_u[1].hypot(self.axis_v[1])
    }
}

/// The band height exponent `k` (band = `2^k` texel rows) for an ellipse `2·half_height` rows
/// tall: the smallest `k ≥ −8` with `2·half_height ≤ MAX_ROWS·2^k`. `None` beyond `2^40`.
pub fn level_for(half_height: f64) -> Option<i32> {
    if !half_height.is_finite() || half_height < 0.0 {
        return None;
    }
    let rows = 2.0 * half_height / MAX_ROWS;
    let k = if rows <= MIN_BAND {
        MIN_LEVEL
    } else {
        (rows.log2().ceil() as i32).max(MIN_LEVEL)
    };
    // Guard the log2's rounding: the band must hold the ellipse in MAX_ROWS bands.
    let k = if 2.0 * half_height > MAX_ROWS * 2f64.powi(k) {
        k + 1
    } else {
        k
    };
    (k <= MAX_LEVEL).then_some(k)
}

impl AreaTable {
    /// Builds the table of a `width` × `height` image whose texels are `texels`, row-major
    /// from the top row (O(W·H)).
    pub fn build(width: u32, height: u32, texels: &[[f32; 3]]) -> Self {
        let (w, h) = (width as usize, height as usize);
        let texel = |i: usize, j: usize| texels[j * w + i];
        let mut mean = [0.0; 3];
        for j in 0..h {
            for i in 0..w {
                let t = texel(i, j);
                for c in 0..3 {
                    mean[c] += t[c] as f64;
                }
            }
        }
        mean = mean.map(|m| m / (w * h) as f64);
        let stride = w + 1;
        let mut sat = vec![[0.0; 3]; stride * (h + 1)];
        for j in 0..h {
            let mut row = [0.0; 3];
            for i in 0..w {
                let t = texel(i, j);
                for c in 0..3 {
                    row[c] += t[c] as f64 - mean[c];
                    sat[(j + 1) * stride + i + 1][c] = sat[j * stride + i + 1][c] + row[c];
                }
            }
        }
        Self {
            width: w,
            height: h,
            mean,
            inv_w: 1.0 / w as f64,
            inv_h: 1.0 / h as f64,
            sat,
        }
    }

    #[inline]
    fn s(&self, i: usize, j: usize) -> [f64; 3] {
        self.sat[j * (self.width + 1) + i]
    }

    /// `F(x, y)` of the mean-free texture for `0 ≤ x ≤ W`, `0 ≤ y ≤ H`: bilinear in the cell.
    #[inline]
    fn inside(&self, x: f64, y: f64) -> [f64; 3] {
        // `v as usize` is `v.floor() as usize` for every v (the cast truncates toward zero and
        // saturates negatives and NaN to 0), without a libm call: the hot path.
        let i = (x as usize).min(self.width - 1);
        let j = (y as usize).min(self.height - 1);
        let (fx, fy) = (x - i as f64, y - j as f64);
        if fy == 0.0 {
            // On a table row (bands of level k ≥ 0 start and end on rows): half the reads.
            let (a, b) = (self.s(i, j), self.s(i + 1, j));
            return std::array::from_fn(|k| a[k] + fx * (b[k] - a[k]));
        }
        let (a, b, c, d) = (
            self.s(i, j),
            self.s(i + 1, j),
            self.s(i, j + 1),
            self.s(i + 1, j + 1),
        );
        std::array::from_fn(|k| {
            let top = a[k] + fx * (b[k] - a[k]);
            let bottom = c[k] + fx * (d[k] - c[k]);
            top + fy * (bottom - top)
        })
    }

    /// `F(x, y) = ∫_0^x ∫_0^y (f − mean)` for any real `x`, `y`, `f` extended by `wrap`.
    fn extended(&self, x: f64, y: f64, wrap: Wrap) -> [f64; 3] {
        let (w, h) = (self.width as f64, self.height as f64);
        match wrap {
            Wrap::Repeat => {
                // Whole periods integrate to zero (mean removed); the remainders remain.
                // F(q_x W + r_x, y) = q_x F(W, y) + F(r_x, y), and F(W, y) is a sum over whole
                // rows of periods only in y, so it is kept.
                // floor and a multiply, not `rem_euclid` (an fmod: the hot path's main cost).
                let (qx, qy) = ((x * self.inv_w).floor(), (y * self.inv_h).floor());
                let (rx, ry) = ((x - qx * w).clamp(0.0, w), (y - qy * h).clamp(0.0, h));
                let (a, b, c, d) = (
                    self.inside(w, h),
                    self.inside(w, ry),
                    self.inside(rx, h),
                    self.inside(rx, ry),
                );
                std::array::from_fn(|k| qx * qy * a[k] + qx * b[k] + qy * c[k] + d[k])
            }
            Wrap::Clamp => {
                let (cx, cy) = (x.clamp(0.0, w), y.clamp(0.0, h));
                let (ex, ey) = (x - cx, y - cy);
                let mut f = self.inside(cx, cy);
                // Edge column (left or right) integrated up to cy; edge row up to cx.
                let ei = if x > w { self.width - 1 } else { 0 };
                let ej = if y > h { self.height - 1 } else { 0 };
                if ex != 0.0 {
                    let (p, q) = (self.inside(ei as f64, cy), self.inside(ei as f64 + 1.0, cy));
                    for k in 0..3 {
                        f[k] += ex * (q[k] - p[k]);
                    }
                }
                if ey != 0.0 {
                    let (p, q) = (self.inside(cx, ej as f64), self.inside(cx, ej as f64 + 1.0));
                    for k in 0..3 {
                        f[k] += ey * (q[k] - p[k]);
                    }
                }
                if ex != 0.0 && ey != 0.0 {
                    let s = |i: usize, j: usize| self.s(i, j);
                    let (a, b, c, d) = (s(ei, ej), s(ei + 1, ej), s(ei, ej + 1), s(ei + 1, ej + 1));
                    for k in 0..3 {
                        f[k] += ex * ey * (d[k] - b[k] - c[k] + a[k]);
                    }
                }
                f
            }
        }
    }

    /// A row position `y ∈ [0, H]`: its cell row and fraction.
    #[inline]
    fn row(&self, y: f64) -> (usize, f64) {
        let j = (y as usize).min(self.height - 1);
        (j, y - j as f64)
    }

    /// `F(x, y1) − F(x, y0)` under `repeat`, as a function of `x` with the y terms
    /// computed once (the hot path of [`AreaTable::ellipse_average`]: two calls per strip).
    fn repeat_band(&self, y0: f64, y1: f64) -> impl Fn(f64) -> [f64; 3] + '_ {
        let (w, h) = (self.width as f64, self.height as f64);
        let split = |y: f64| {
            let q = (y * self.inv_h).floor();
            (q, (y - q * h).clamp(0.0, h))
        };
        let ((q0, r0), (q1, r1)) = (split(y0), split(y1));
        let dq = q1 - q0;
        let (a, b1, b0) = (self.inside(w, h), self.inside(w, r1), self.inside(w, r0));
        let per_period: [f64; 3] = std::array::from_fn(|k| dq * a[k] + b1[k] - b0[k]);
        let (row0, row1) = (self.row(r0), self.row(r1));
        let top = self.height;
        move |x: f64| {
            let qx = (x * self.inv_w).floor();
            let rx = (x - qx * w).clamp(0.0, w);
            let i = (rx as usize).min(self.width - 1);
            let fx = rx - i as f64;
            let lerp = |j: usize, k: usize| {
                let (p, q) = (self.s(i, j)[k], self.s(i + 1, j)[k]);
                p + fx * (q - p)
            };
            std::array::from_fn(|k| {
                let d = |(j, fy): (usize, f64)| {
                    let lo = lerp(j, k);
                    lo + fy * (lerp(j + 1, k) - lo)
                };
                qx * per_period[k] + dq * lerp(top, k) + d(row1) - d(row0)
            })
        }
    }

    /// The integral of the nearest-filtered texture (extended by `wrap`) over the rectangle
    /// `[x0, x1] × [y0, y1]` in texel coordinates (texel units² × value), exact to rounding.
    pub fn rect_integral(&self, x0: f64, x1: f64, y0: f64, y1: f64, wrap: Wrap) -> [f64; 3] {
        let (a, b, c, d) = (
            self.extended(x1, y1, wrap),
            self.extended(x0, y1, wrap),
            self.extended(x1, y0, wrap),
            self.extended(x0, y0, wrap),
        );
        let area = (x1 - x0) * (y1 - y0);
        std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k] + self.mean[k] * area)
    }

    /// The uniform area average of the nearest-filtered texture (extended by `wrap`) over the
    /// ellipse `e` (see the module docs for the strips and the error bound). `None` for a
    /// non-finite or zero-area ellipse, or one taller than `2^40·MAX_ROWS` rows.
    pub fn ellipse_average(&self, e: &TexelEllipse, wrap: Wrap) -> Option<[f64; 3]> {
        let [mut cx, mut cy] = e.centre;
        let (w, h) = (self.width as f64, self.height as f64);
        if wrap == Wrap::Repeat && cx.is_finite() && cy.is_finite() {
            // Whole periods do not change the average: keep the coordinates small.
            cx -= (cx * self.inv_w).floor() * w;
            cy -= (cy * self.inv_h).floor() * h;
        }
        let (au, av) = (e.axis_u, e.axis_v);
        let det = au[0] * av[1] - au[1] * av[0];
        let hy = e.half_height();
        let scale = au[0].hypot(au[1]) * av[0].hypot(av[1]);
        if !(cx.is_finite() && cy.is_finite() && det.is_finite() && scale.is_finite())
            || det.abs() <= 1e-12 * scale
            || hy <= 0.0
        {
            return None;
        }
        let k = level_for(hy)?;
        let band = 2f64.powi(k);
        // Chord at height y = cy + dy: centre cx + shear·dy, half-width hw0·√(1 − (dy/hy)²),
        // with shear = S12/S22 and hw0 = |det M|/hy (S = M Mᵀ).
        let shear = (au[0] * au[1] + av[0] * av[1]) / (hy * hy);
        let hw0 = det.abs() / hy;
        // ∫_{−1}^{z} 2√(1 − t²) dt = G(z) + π/2 with G(z) = z√(1 − z²) + asin z.
        let g = |z: f64| {
            let z = z.clamp(-1.0, 1.0);
            z * (1.0 - z * z).sqrt() + z.asin()
        };
        let (top, bottom) = (cy - hy, cy + hy);
        let first = (top / band).floor();
        let last = (bottom / band).floor();
        let mut sum = [0.0; 3];
        let mut b = first;
        let mut g0 = g(-1.0);
        while b <= last {
            let y0 = (b * band).max(top);
            let y1 = ((b + 1.0) * band).min(bottom);
            b += 1.0;
            if y1 <= y0 {
                continue;
            }
            // Exact area of the ellipse within the strip: hw0·hy·(G(z1) − G(z0)); G(z0) is
            // the previous strip's G(z1).
            let g1 = g((y1 - cy) / hy);
            let area = hw0 * hy * (g1 - g0);
            g0 = g1;
            if area <= 0.0 {
                continue;
            }
            let half = 0.5 * area / (y1 - y0);
            let xc = cx + shear * (0.5 * (y0 + y1) - cy);
            let (x0, x1) = (xc - half, xc + half);
            let i = if y0 >= 0.0 && y1 <= h && x0 >= 0.0 && x1 <= w {
                // Inside the table: no wrap to apply, and rows read directly (the common
                // case once the centre is brought into the first period).
                let f = |x: f64, y: f64| self.inside(x, y);
                let (a, b, c, d) = (f(x1, y1), f(x0, y1), f(x1, y0), f(x0, y0));
                std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k] + self.mean[k] * area)
            } else {
                match wrap {
                    Wrap::Repeat => {
                        let band = self.repeat_band(y0, y1);
                        let (r1, r0) = (band(xc + half), band(xc - half));
                        std::array::from_fn(|k| r1[k] - r0[k] + self.mean[k] * area)
                    }
                    Wrap::Clamp => self.rect_integral(x0, x1, y0, y1, wrap),
                }
            };
            for c in 0..3 {
                sum[c] += i[c];
            }
        }
        let total = std::f64::consts::PI * det.abs();
        let avg = sum.map(|s| s / total);
        avg.iter().all(|v| v.is_finite()).then_some(avg)
    }

    /// How many strips [`AreaTable::ellipse_average`] integrates for `e` (for tests and
    /// docs): at most `MAX_ROWS + 1`.
    pub fn strip_count(e: &TexelEllipse) -> Option<usize> {
        let hy = e.half_height();
        let band = 2f64.powi(level_for(hy)?);
        let (top, bottom) = (e.centre[1] - hy, e.centre[1] + hy);
        Some(((bottom / band).floor() - (top / band).floor()) as usize + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image as the table sees it (the tests need no decoding).
    struct Texture {
        width: u32,
        height: u32,
        texels: Vec<[f32; 3]>,
    }

    impl Texture {
        fn from_texels(_: &str, width: u32, height: u32, texels: Vec<[f32; 3]>) -> Option<Self> {
            Some(Self {
                width,
                height,
                texels,
            })
        }
        fn texel(&self, i: u32, j: u32) -> [f32; 3] {
            self.texels[j as usize * self.width as usize + i as usize]
        }
    }

    fn table_of(t: &Texture) -> AreaTable {
        AreaTable::build(t.width, t.height, &t.texels)
    }

    fn texture(w: u32, h: u32, seed: u64) -> Texture {
        let mut rng = crate::rng::Rng::from_keys(seed, &[]);
        let texels = (0..w * h)
            .map(|_| {
                let v = rng.uniform() as f32;
                [v, 2.0 * v * v, (1.0 - v) * 3.0]
            })
            .collect();
        Texture::from_texels("t", w, h, texels).unwrap()
    }

    /// Brute force: Σ over the texels of the extended image of overlap area × value.
    fn brute(t: &Texture, x0: f64, x1: f64, y0: f64, y1: f64, wrap: Wrap) -> [f64; 3] {
        let (w, h) = (t.width as i64, t.height as i64);
        let mut out = [0.0; 3];
        for j in y0.floor() as i64..y1.ceil() as i64 {
            for i in x0.floor() as i64..x1.ceil() as i64 {
                let ox = (x1.min(i as f64 + 1.0) - x0.max(i as f64)).max(0.0);
                let oy = (y1.min(j as f64 + 1.0) - y0.max(j as f64)).max(0.0);
                let (ii, jj) = match wrap {
                    Wrap::Repeat => (i.rem_euclid(w), j.rem_euclid(h)),
                    Wrap::Clamp => (i.clamp(0, w - 1), j.clamp(0, h - 1)),
                };
                let v = t.texel(ii as u32, jj as u32);
                for c in 0..3 {
                    out[c] += ox * oy * v[c] as f64;
                }
            }
        }
        out
    }

    #[test]
    fn rectangle_integrals_equal_brute_force() {
        let t = texture(7, 5, 3);
        let table = table_of(&t);
        let mut rng = crate::rng::Rng::from_keys(9, &[]);
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            for n in 0..500 {
                // Inside, straddling the edges, and far outside (several periods).
                let spread = [8.0, 20.0, 60.0][n % 3];
                let x0 = (rng.uniform() - 0.4) * spread;
                let y0 = (rng.uniform() - 0.4) * spread;
                let x1 = x0 + rng.uniform() * spread / 2.0;
                let y1 = y0 + rng.uniform() * spread / 2.0;
                let got = table.rect_integral(x0, x1, y0, y1, wrap);
                let want = brute(&t, x0, x1, y0, y1, wrap);
                for c in 0..3 {
                    let tol = 1e-11 * (1.0 + want[c].abs());
                    assert!(
                        (got[c] - want[c]).abs() <= tol,
                        "{wrap:?} [{x0}, {x1}]×[{y0}, {y1}] c{c}: {} vs {}",
                        got[c],
                        want[c]
                    );
                }
            }
        }
    }

    #[test]
    fn level_choice_bounds_the_strips() {
        assert_eq!(level_for(0.0), Some(MIN_LEVEL));
        assert_eq!(level_for(16.0), Some(0));
        assert_eq!(level_for(16.01), Some(1));
        assert_eq!(level_for(4.0), Some(-2));
        assert_eq!(level_for(f64::NAN), None);
        assert_eq!(level_for(1e300), None);
        let mut rng = crate::rng::Rng::from_keys(5, &[]);
        for _ in 0..2000 {
            let r = 10f64.powf(rng.uniform() * 8.0 - 2.0);
            let a = rng.uniform() * 6.3;
            let e = TexelEllipse {
                centre: [rng.uniform() * 1e3, (rng.uniform() - 0.5) * 1e4],
                axis_u: [r * a.cos(), r * a.sin()],
                axis_v: [-0.3 * r * a.sin(), 0.3 * r * a.cos()],
            };
            let k = level_for(e.half_height()).unwrap();
            let n = AreaTable::strip_count(&e).unwrap();
            assert!(n <= MAX_ROWS as usize + 1, "{n} strips for {e:?}");
            // The level is the smallest that fits: one level finer would need > MAX_ROWS.
            if k > MIN_LEVEL {
                assert!(2.0 * e.half_height() > MAX_ROWS * 2f64.powi(k - 1));
            }
        }
    }

    #[test]
    fn a_constant_texture_averages_to_itself_and_degenerate_ellipses_decline() {
        let t = Texture::from_texels("c", 3, 2, vec![[0.25, 0.5, 2.0]; 6]).unwrap();
        let table = table_of(&t);
        let e = TexelEllipse {
            centre: [-40.0, 17.5],
            axis_u: [30.0, 20.0],
            axis_v: [-2.0, 3.0],
        };
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let a = table.ellipse_average(&e, wrap).unwrap();
            for (got, want) in a.iter().zip([0.25, 0.5, 2.0]) {
                assert!((got - want).abs() < 1e-12, "{got} vs {want}");
            }
        }
        let flat = TexelEllipse {
            axis_v: [0.0, 0.0],
            ..e
        };
        assert!(table.ellipse_average(&flat, Wrap::Repeat).is_none());
        let nan = TexelEllipse {
            centre: [f64::NAN, 0.0],
            ..e
        };
        assert!(table.ellipse_average(&nan, Wrap::Clamp).is_none());
    }

    /// The exact mean of the nearest-filtered, repeating texture `t` (channel 0) over `e`,
    /// independently of the strips: the ellipse cut into chords along `axis_u`, each chord's
    /// integral exact from its crossings of the texel edges, the chords' offset along `axis_v`
    /// integrated by the midpoint rule in y = sin θ (4,000 nodes). Thin ellipses are cut along
    /// their length, so the integrand varies slowly whatever the aspect.
    fn exact_mean(t: &Texture, e: &TexelEllipse) -> f64 {
        let n = 4000;
        let (w, h) = (t.width as i64, t.height as i64);
        let value = |x: f64, y: f64| {
            let (i, j) = (
                (x.floor() as i64).rem_euclid(w),
                (y.floor() as i64).rem_euclid(h),
            );
            f64::from(t.texel(i as u32, j as u32)[0])
        };
        let mut total = 0.0;
        for k in 0..n {
            let theta =
                -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
            let (y, half) = (theta.sin(), theta.cos());
            let base = [e.centre[0] + y * e.axis_v[0], e.centre[1] + y * e.axis_v[1]];
            let mut cuts = vec![-half, half];
            for (c, d) in [(base[0], e.axis_u[0]), (base[1], e.axis_u[1])] {
                if d == 0.0 {
                    continue;
                }
                let (lo, hi) = (c - half * d.abs(), c + half * d.abs());
                let mut edge = lo.ceil();
                while edge <= hi {
                    let x = (edge - c) / d;
                    if x > -half && x < half {
                        cuts.push(x);
                    }
                    edge += 1.0;
                }
            }
            cuts.sort_by(f64::total_cmp);
            let chord: f64 = cuts
                .windows(2)
                .map(|x| {
                    let m = 0.5 * (x[0] + x[1]);
                    value(base[0] + m * e.axis_u[0], base[1] + m * e.axis_u[1]) * (x[1] - x[0])
                })
                .sum();
            // (2/π) cos²θ dθ per chord, times the chord's mean.
            total += 2.0 / n as f64 * half * half * chord / (2.0 * half);
        }
        total
    }

    /// The strips' error on thin ellipses, as documented in the module docs ("Error"): for
    /// ellipses 20 texels long (semi-major axis 10) at aspects b/a from 1 to 0.001, random
    /// orientations and centres on a random texture (values uniform in [0, 1], so the errors
    /// are fractions of the contrast), the mean and largest |error| against [`exact_mean`].
    /// Run with `cargo test -p het-bssrdf-tracer --release area_table::tests::thin -- --ignored
    /// --nocapture`.
    #[test]
    #[ignore]
    fn thin_ellipse_errors() {
        let t = texture(64, 64, 11);
        let table = table_of(&t);
        let mut rng = crate::rng::Rng::from_keys(38, &[]);
        for aspect in [1.0, 0.3, 0.1, 0.03, 0.01, 0.003, 0.001] {
            let (mut sum, mut max, n) = (0.0f64, 0.0f64, 400);
            for _ in 0..n {
                let angle = std::f64::consts::TAU * rng.uniform();
                let (s, c) = angle.sin_cos();
                let e = TexelEllipse {
                    centre: [64.0 * rng.uniform(), 64.0 * rng.uniform()],
                    axis_u: [10.0 * c, 10.0 * s],
                    axis_v: [-10.0 * aspect * s, 10.0 * aspect * c],
                };
                let got = table.ellipse_average(&e, Wrap::Repeat).unwrap()[0];
                let err = (got - exact_mean(&t, &e)).abs();
                sum += err;
                max = max.max(err);
            }
            eprintln!(
                "b/a {aspect}: mean |error| {:.2} % of the contrast, largest {:.2} %",
                100.0 * sum / n as f64,
                100.0 * max
            );
        }
    }
}
