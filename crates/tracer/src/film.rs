//! The film: a row-major RGB image (row 0 at the top).

use bssrdf_core::Rgb;

/// An RGB image of linear radiance values, row-major, row 0 at the top, pixel `(x, y)` at
/// index `y · width + x`.
#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width · height` values.
    pub pixels: Vec<Rgb>,
}

impl Film {
    /// A black film.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Rgb::ZERO; width as usize * height as usize],
        }
    }

    /// Index of pixel `(x, y)` in [`Film::pixels`].
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        debug_assert!(x < self.width && y < self.height);
        y as usize * self.width as usize + x as usize
    }

    /// The value of pixel `(x, y)`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[self.index(x, y)]
    }

    /// Sets pixel `(x, y)`.
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, v: Rgb) {
        let i = self.index(x, y);
        self.pixels[i] = v;
    }

    /// Adds `v` to pixel `(x, y)`.
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, v: Rgb) {
        debug_assert!(v.is_finite(), "non-finite film contribution {v:?}");
        let i = self.index(x, y);
        self.pixels[i] += v;
    }

    /// Multiplies every pixel by `s` (e.g. 1/spp).
    pub fn scale(&mut self, s: f64) {
        for p in &mut self.pixels {
            *p *= s;
        }
    }

    /// The film as an EXR written by [`crate::output::write_exr`] holds it: every value
    /// rounded to `f32`. Previews and statistics made from this film equal those made from
    /// the file, so that an image assembled from files (a merge of shards) reproduces them.
    pub fn as_stored(&self) -> Film {
        let round = |v: f64| f64::from(v as f32);
        Film {
            width: self.width,
            height: self.height,
            pixels: self
                .pixels
                .iter()
                .map(|p| Rgb::new(round(p[0]), round(p[1]), round(p[2])))
                .collect(),
        }
    }

    /// Mean over all pixels.
    pub fn mean(&self) -> Rgb {
        if self.pixels.is_empty() {
            return Rgb::ZERO;
        }
        let mut s = Rgb::ZERO;
        for p in &self.pixels {
            s += *p;
        }
        s / self.pixels.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_row_major_top_down() {
        let mut f = Film::new(3, 2);
        f.set(2, 0, Rgb::ONE);
        f.add(0, 1, Rgb::splat(2.0));
        f.add(0, 1, Rgb::splat(1.0));
        assert_eq!(f.pixels[2], Rgb::ONE);
        assert_eq!(f.pixels[3], Rgb::splat(3.0));
        f.scale(0.5);
        assert_eq!(f.get(0, 1), Rgb::splat(1.5));
        assert!((f.mean().0[0] - (0.5 + 1.5) / 6.0).abs() < 1e-15);
    }
}
