//! The shape correction's factors as the render reads them: f(x, ω) per channel at direction
//! nodes ([`Directional`]) on sample points of an object's surface, and their lookup at a hit
//! (barycentric over the mesh's vertices, or a Gaussian-weighted neighbourhood of samples).
//! What f is and how it is measured: the parent module, [`super`] (docs/shapes.md, "The shape
//! correction"). A module of its own so that the BSSRDF (`integrator::bssrdf`), which reads the
//! factors, and the measurement, which evaluates the BSSRDF, do not import each other.

use std::f64::consts::TAU;

use bssrdf_core::Rgb;
use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::Hit;
use crate::volume::orthonormal_basis;

/// Exit cosines μ at which the walks start (the factor is linear in μ between them and
/// constant beyond).
pub const MU_NODES: [f64; 5] = [0.1, 0.325, 0.55, 0.775, 1.0];
/// Exit azimuths per cosine, equally spaced in the tangent frame of the shading normal
/// (`het_estimate::frame::orthonormal_basis`); the factor is periodic-linear between them.
pub const PHI_NODES: usize = 6;
/// Directions per point: [`MU_NODES`] × [`PHI_NODES`], index `j · PHI_NODES + k`.
pub const DIRECTIONS: usize = MU_NODES.len() * PHI_NODES;

/// The correction's directional factor f(ω) at one surface point, per channel, at the
/// direction nodes ([`DIRECTIONS`]): S is scaled by f(x_i, ω_i)·f(x_o, ω_o).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Directional(pub [Rgb; DIRECTIONS]);

impl Directional {
    /// No correction.
    pub const ONE: Directional = Directional([Rgb::ONE; DIRECTIONS]);

    /// ⟨f⟩ over uniform incident light, per channel ([`super::incident_weights`]).
    #[inline]
    pub fn incident_mean(&self, weights: &[f64; DIRECTIONS]) -> Rgb {
        let mut m = Rgb::ZERO;
        for (f, w) in self.0.iter().zip(weights) {
            m += *f * *w;
        }
        m
    }

    /// f along the unit direction `w` outside the medium, about the unit normal `n` (the
    /// shading normal the correction was sampled about).
    #[inline]
    pub fn along(&self, w: DVec3, n: DVec3) -> Rgb {
        let (t, b) = orthonormal_basis(n);
        let mu = w.dot(n).clamp(0.0, 1.0);
        let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(TAU);
        self.at(mu, phi)
    }

    /// f at exit cosine `mu` and azimuth `phi` ∈ [0, 2π).
    #[inline]
    pub fn at(&self, mu: f64, phi: f64) -> Rgb {
        let x = phi / TAU * PHI_NODES as f64;
        let k0 = (x as usize).min(PHI_NODES - 1);
        let k1 = (k0 + 1) % PHI_NODES;
        let s = (x - k0 as f64).clamp(0.0, 1.0);
        let row =
            |j: usize| self.0[j * PHI_NODES + k0] * (1.0 - s) + self.0[j * PHI_NODES + k1] * s;
        let [(j0, w0), (j1, w1)] = mu_weights(mu);
        row(j0) * w0 + row(j1) * w1
    }
}

/// One sample point of the correction.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    /// The point.
    pub p: DVec3,
    /// Its shading normal, about which `f`'s directions are measured.
    pub n: DVec3,
    /// f at the point.
    pub f: Directional,
}

/// The correction of one object: sample points and a uniform grid over them.
#[derive(Debug)]
pub(crate) struct ShapeCorrection {
    /// The sample points, with f measured at each.
    pub(super) samples: Vec<Sample>,
    /// A grid over the samples' positions.
    pub(super) grid: Grid,
    /// f at the mesh's vertices and its triangles, when no edge is longer than h: a lookup is
    /// then a barycentric interpolation ([`ShapeCorrection::at_hit`]) instead of a
    /// neighbourhood query.
    pub(super) vertices: Option<(Vec<Directional>, Vec<[u32; 3]>)>,
    /// Wall time of the build (s).
    pub(super) seconds: f64,
}

/// A uniform grid over sample points, for Gaussian-weighted neighbourhood sums.
#[derive(Debug)]
pub(super) struct Grid {
    /// Gaussian width h (length); neighbours within 2h count.
    pub(super) h: f64,
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    /// CSR: points of cell k are `order[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    order: Vec<u32>,
}

impl Grid {
    pub(super) fn new(points: &[DVec3], h: f64, lo: DVec3, hi: DVec3) -> Self {
        let cell = 2.0 * h;
        let lo = lo - DVec3::splat(cell);
        let span = hi + DVec3::splat(cell) - lo;
        let dims = [0, 1, 2].map(|k| ((span[k] / cell).ceil() as usize).clamp(1, 256));
        let cell_of = |p: DVec3| -> usize {
            let q = [0, 1, 2].map(|k| (((p[k] - lo[k]) / cell) as usize).min(dims[k] - 1));
            (q[2] * dims[1] + q[1]) * dims[0] + q[0]
        };
        let n_cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; n_cells + 1];
        for &p in points {
            start[cell_of(p) + 1] += 1;
        }
        for k in 0..n_cells {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; points.len()];
        for (i, &p) in points.iter().enumerate() {
            let k = cell_of(p);
            order[fill[k] as usize] = i as u32;
            fill[k] += 1;
        }
        Self {
            h,
            lo,
            cell,
            dims,
            start,
            order,
        }
    }

    /// [`Grid::for_each_near`] about `hits[i]`, the grid being built over `hits`' positions.
    #[inline]
    pub(super) fn around(&self, hits: &[Hit], i: usize, f: impl FnMut(usize, f64)) {
        self.for_each_near(hits[i].p, hits[i].ns, |j| hits[j].p, |j| hits[j].ns, f)
    }

    /// Calls `f(i, w)` for every point i within 2h of `p` whose normal faces like `n`, with
    /// the weight w = exp(−d²/2h²)·(n·n_i)²; `position(i)` and `normal(i)` read the points.
    #[inline]
    fn for_each_near(
        &self,
        p: DVec3,
        n: DVec3,
        position: impl Fn(usize) -> DVec3,
        normal: impl Fn(usize) -> DVec3,
        mut f: impl FnMut(usize, f64),
    ) {
        let q = [0, 1, 2].map(|k| ((p[k] - self.lo[k]) / self.cell).floor() as i64);
        let inv = 1.0 / (2.0 * self.h * self.h);
        let cut = 4.0 * self.h * self.h;
        for dz in -1..=1 {
            let z = q[2] + dz;
            if z < 0 || z >= self.dims[2] as i64 {
                continue;
            }
            for dy in -1..=1 {
                let y = q[1] + dy;
                if y < 0 || y >= self.dims[1] as i64 {
                    continue;
                }
                for dx in -1..=1 {
                    let x = q[0] + dx;
                    if x < 0 || x >= self.dims[0] as i64 {
                        continue;
                    }
                    let k = ((z as usize * self.dims[1]) + y as usize) * self.dims[0] + x as usize;
                    for &i in &self.order[self.start[k] as usize..self.start[k + 1] as usize] {
                        let i = i as usize;
                        let d2 = (position(i) - p).length_squared();
                        let facing = normal(i).dot(n);
                        if d2 > cut || facing <= 0.0 {
                            continue;
                        }
                        f(i, (-d2 * inv).exp() * facing * facing);
                    }
                }
            }
        }
    }
}

impl ShapeCorrection {
    /// f at every vertex of `mesh` (the neighbourhood query at the vertex, about its
    /// area-weighted normal), when the mesh is fine enough for barycentric interpolation to
    /// follow f: no edge longer than h.
    pub(super) fn vertex_factors(
        &self,
        mesh: &crate::geometry::TriangleMesh,
    ) -> Option<(Vec<Directional>, Vec<[u32; 3]>)> {
        let h = self.grid.h;
        let mut normals = vec![DVec3::ZERO; mesh.positions.len()];
        for (i, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = mesh.triangle_vertices(i);
            if (b - a).length() > h || (c - b).length() > h || (a - c).length() > h {
                return None;
            }
            let n = (b - a).cross(c - a);
            for &v in tri {
                normals[v as usize] += n;
            }
        }
        let f = mesh
            .positions
            .par_iter()
            .zip(&normals)
            .map(|(&p, n)| self.at(p, n.normalize_or_zero()))
            .collect();
        Some((f, mesh.triangles.clone()))
    }

    /// f at a hit on the object: barycentric interpolation of the vertices' f where the mesh
    /// is fine enough, else the neighbourhood query ([`ShapeCorrection::at`]).
    #[inline]
    pub fn at_hit(&self, hit: &Hit) -> Directional {
        match &self.vertices {
            Some((f, tris)) if (hit.prim as usize) < tris.len() => {
                let [i0, i1, i2] = tris[hit.prim as usize];
                let (b1, b2) = (hit.bary.x, hit.bary.y);
                let b0 = 1.0 - b1 - b2;
                let (f0, f1, f2) = (&f[i0 as usize].0, &f[i1 as usize].0, &f[i2 as usize].0);
                Directional(std::array::from_fn(|d| {
                    f0[d] * b0 + f1[d] * b1 + f2[d] * b2
                }))
            }
            _ => self.at(hit.p, hit.ns),
        }
    }

    /// What the build did: sample points, spacing h and wall time (s), for the render's notes.
    pub fn summary(&self) -> (usize, f64, f64) {
        (self.samples.len(), self.grid.h, self.seconds)
    }

    /// f at a surface point: the Gaussian-weighted mean of the samples within 2h whose normals
    /// face like `n`; 1 where none is near.
    pub fn at(&self, p: DVec3, n: DVec3) -> Directional {
        let mut sum = [Rgb::ZERO; DIRECTIONS];
        let mut wsum = 0.0;
        self.grid.for_each_near(
            p,
            n,
            |i| self.samples[i].p,
            |i| self.samples[i].n,
            |i, w| {
                for (acc, f) in sum.iter_mut().zip(self.samples[i].f.0) {
                    *acc += f * w;
                }
                wsum += w;
            },
        );
        if wsum > 0.0 {
            Directional(sum.map(|v| v * (1.0 / wsum)))
        } else {
            Directional::ONE
        }
    }
}

/// Linear interpolation in μ between [`MU_NODES`] (constant beyond them), as two (node,
/// weight) pairs.
#[inline]
pub(super) fn mu_weights(mu: f64) -> [(usize, f64); 2] {
    let last = MU_NODES.len() - 1;
    if mu <= MU_NODES[0] {
        return [(0, 1.0), (0, 0.0)];
    }
    for j in 1..=last {
        if mu <= MU_NODES[j] {
            let t = (mu - MU_NODES[j - 1]) / (MU_NODES[j] - MU_NODES[j - 1]);
            return [(j - 1, 1.0 - t), (j, t)];
        }
    }
    [(last, 1.0), (last, 0.0)]
}
