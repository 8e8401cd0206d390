//! Equal-area bins over the unit sphere, for the samplers' χ² tests (the environment map's,
//! the rough dielectric's): `nt` bands of equal height in z (so of equal area, by Archimedes'
//! hat-box theorem) times `np` equal sectors in φ.

use std::f64::consts::PI;

use glam::DVec3;

/// `nt` × `np` equal-area bins over the sphere (module docs).
pub(crate) struct SphereBins {
    pub nt: usize,
    pub np: usize,
}

impl SphereBins {
    /// The number of bins.
    pub fn len(&self) -> usize {
        self.nt * self.np
    }

    /// The bin of the unit direction `d`: band a from z = 1 down, sector c from φ = 0.
    pub fn index(&self, d: DVec3) -> usize {
        let a = (((1.0 - d.z) / 2.0 * self.nt as f64) as usize).min(self.nt - 1);
        let phi = d.y.atan2(d.x).rem_euclid(2.0 * PI);
        let c = ((phi / (2.0 * PI) * self.np as f64) as usize).min(self.np - 1);
        a * self.np + c
    }

    /// The probability of each bin under `density` (per unit solid angle): the midpoint rule
    /// on `sub` × `sub` cells of equal area per bin.
    pub fn probabilities(&self, sub: usize, density: impl Fn(DVec3) -> f64) -> Vec<f64> {
        let (nt, np) = (self.nt as f64, self.np as f64);
        let mut p = vec![0.0; self.len()];
        for a in 0..self.nt {
            for c in 0..self.np {
                let mut s = 0.0;
                for x in 0..sub {
                    for y in 0..sub {
                        let cos = 1.0 - 2.0 * (a as f64 + (x as f64 + 0.5) / sub as f64) / nt;
                        let sin = (1.0 - cos * cos).max(0.0).sqrt();
                        let phi = 2.0 * PI * (c as f64 + (y as f64 + 0.5) / sub as f64) / np;
                        s += density(DVec3::new(sin * phi.cos(), sin * phi.sin(), cos));
                    }
                }
                p[a * self.np + c] = s / (sub * sub) as f64 * 4.0 * PI / (nt * np);
            }
        }
        p
    }
}
