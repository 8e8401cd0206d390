//! Cameras: map film coordinates to primary rays.
//!
//! Film coordinates are in pixels: `(0, 0)` is the top-left corner of pixel `(0, 0)`, `x`
//! grows to the right and `y` downward (row 0 is the top of the image); the centre of pixel
//! `(i, j)` is `(i + 0.5, j + 0.5)`.

use glam::DVec3;

use crate::geometry::Ray;

/// A perspective (pinhole) or orthographic camera with its resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Camera {
    /// Pinhole camera.
    Perspective(PerspectiveCamera),
    /// Parallel projection.
    Orthographic(OrthographicCamera),
}

/// A camera frame: unit `forward`, `right` and `up` vectors, right-handed image plane
/// (`right = forward × up_hint`, normalised; `up = right × forward`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// View direction.
    pub forward: DVec3,
    /// Image x axis.
    pub right: DVec3,
    /// Image y axis (up on screen).
    pub up: DVec3,
}

impl Frame {
    /// The frame looking along `forward` with `up_hint` giving the screen's up direction.
    /// `None` when either is zero or they are parallel.
    pub fn new(forward: DVec3, up_hint: DVec3) -> Option<Frame> {
        let f = forward.try_normalize()?;
        let r = f.cross(up_hint).try_normalize()?;
        Some(Frame {
            forward: f,
            right: r,
            up: r.cross(f),
        })
    }
}

/// A pinhole camera at `eye`, vertical field of view `fov_y`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerspectiveCamera {
    /// Eye position.
    pub eye: DVec3,
    /// Orientation.
    pub frame: Frame,
    /// `tan(fov_y / 2)`.
    pub tan_half_fov_y: f64,
    /// Resolution in pixels.
    pub width: u32,
    /// Resolution in pixels.
    pub height: u32,
}

/// A parallel projection: rays start on the plane through `centre` perpendicular to
/// `direction` (anything behind that plane is not seen) and travel along `direction`. The
/// view rectangle, `view_width × view_height` scene units centred on `centre`, maps exactly
/// onto the film.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrthographicCamera {
    /// Centre of the view rectangle.
    pub centre: DVec3,
    /// Orientation (`forward` = the view direction).
    pub frame: Frame,
    /// Width of the view rectangle (scene units).
    pub view_width: f64,
    /// Height of the view rectangle (scene units).
    pub view_height: f64,
    /// Resolution in pixels.
    pub width: u32,
    /// Resolution in pixels.
    pub height: u32,
}

/// Invalid camera parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CameraError {
    /// The view direction is zero, or parallel to `up`.
    #[error("the view direction must be non-zero and not parallel to `up`")]
    BadFrame,
    /// fov_y outside (0°, 180°).
    #[error("fov_y must be in (0, 180) degrees, got {0}")]
    BadFov(f64),
    /// A view size that is not finite and positive.
    #[error("the view width and height must be finite and positive, got {0} x {1}")]
    BadViewSize(f64, f64),
    /// A zero resolution.
    #[error("the resolution must be at least 1x1, got {0}x{1}")]
    BadResolution(u32, u32),
    /// A non-finite position.
    #[error("camera positions must be finite")]
    NonFinite,
}

impl Camera {
    /// A pinhole camera at `eye` looking at `target`; `fov_y_degrees` is the full vertical
    /// field of view.
    pub fn perspective(
        eye: DVec3,
        target: DVec3,
        up: DVec3,
        fov_y_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(CameraError::NonFinite);
        }
        if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
            return Err(CameraError::BadFov(fov_y_degrees));
        }
        check_resolution(width, height)?;
        let frame = Frame::new(target - eye, up).ok_or(CameraError::BadFrame)?;
        Ok(Camera::Perspective(PerspectiveCamera {
            eye,
            frame,
            tan_half_fov_y: (0.5 * fov_y_degrees).to_radians().tan(),
            width,
            height,
        }))
    }

    /// A parallel projection over the `view_width × view_height` rectangle centred on
    /// `centre`, looking along `direction`.
    pub fn orthographic(
        centre: DVec3,
        direction: DVec3,
        up: DVec3,
        view_width: f64,
        view_height: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        if !(centre.is_finite() && direction.is_finite() && up.is_finite()) {
            return Err(CameraError::NonFinite);
        }
        if !(view_width > 0.0
            && view_height > 0.0
            && view_width.is_finite()
            && view_height.is_finite())
        {
            return Err(CameraError::BadViewSize(view_width, view_height));
        }
        check_resolution(width, height)?;
        let frame = Frame::new(direction, up).ok_or(CameraError::BadFrame)?;
        Ok(Camera::Orthographic(OrthographicCamera {
            centre,
            frame,
            view_width,
            view_height,
            width,
            height,
        }))
    }

    /// `(width, height)` in pixels.
    pub fn resolution(&self) -> (u32, u32) {
        match self {
            Camera::Perspective(c) => (c.width, c.height),
            Camera::Orthographic(c) => (c.width, c.height),
        }
    }

    /// The same camera with another resolution (the view itself is unchanged; a perspective
    /// camera keeps its vertical field of view).
    pub fn with_resolution(&self, width: u32, height: u32) -> Result<Camera, CameraError> {
        check_resolution(width, height)?;
        let mut c = *self;
        match &mut c {
            Camera::Perspective(p) => (p.width, p.height) = (width, height),
            Camera::Orthographic(o) => (o.width, o.height) = (width, height),
        }
        Ok(c)
    }

    /// The primary ray through film position `(film_x, film_y)` (pixels, see the module docs).
    #[inline]
    pub fn ray(&self, film_x: f64, film_y: f64) -> Ray {
        match self {
            Camera::Perspective(c) => {
                let (w, h) = (c.width as f64, c.height as f64);
                let sy = (1.0 - 2.0 * film_y / h) * c.tan_half_fov_y;
                let sx = (2.0 * film_x / w - 1.0) * c.tan_half_fov_y * (w / h);
                let d = (c.frame.forward + sx * c.frame.right + sy * c.frame.up).normalize();
                Ray::new(c.eye, d)
            }
            Camera::Orthographic(c) => {
                let (w, h) = (c.width as f64, c.height as f64);
                let x = (film_x / w - 0.5) * c.view_width;
                let y = (0.5 - film_y / h) * c.view_height;
                Ray::new(
                    c.centre + x * c.frame.right + y * c.frame.up,
                    c.frame.forward,
                )
            }
        }
    }
}

fn check_resolution(width: u32, height: u32) -> Result<(), CameraError> {
    if width == 0 || height == 0 {
        Err(CameraError::BadResolution(width, height))
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthographic_pixel_centres_map_to_the_view_rectangle() {
        let c = Camera::orthographic(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::NEG_Z,
            DVec3::Y,
            20.0,
            20.0,
            128,
            128,
        )
        .unwrap();
        let cell = 20.0 / 128.0;
        for (i, j) in [(0u32, 0u32), (127, 0), (0, 127), (64, 31)] {
            let r = c.ray(i as f64 + 0.5, j as f64 + 0.5);
            let x = -10.0 + (i as f64 + 0.5) * cell;
            let y = 10.0 - (j as f64 + 0.5) * cell;
            assert!(
                r.origin.abs_diff_eq(DVec3::new(x, y, 5.0), 1e-12),
                "{i},{j}: {:?}",
                r.origin
            );
            assert_eq!(r.dir, DVec3::NEG_Z);
        }
        // Corners of the film are the corners of the view.
        assert!(
            c.ray(0.0, 0.0)
                .origin
                .abs_diff_eq(DVec3::new(-10.0, 10.0, 5.0), 1e-12)
        );
        assert!(
            c.ray(128.0, 128.0)
                .origin
                .abs_diff_eq(DVec3::new(10.0, -10.0, 5.0), 1e-12)
        );
    }

    #[test]
    fn perspective_fov() {
        let c = Camera::perspective(DVec3::ZERO, DVec3::NEG_Z, DVec3::Y, 90.0, 200, 100).unwrap();
        // Top edge centre: 45° up.
        let top = c.ray(100.0, 0.0).dir;
        assert!((top.angle_between(DVec3::NEG_Z) - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert!(top.y > 0.0);
        // Right edge centre: atan(aspect · tan 45°) = atan(2).
        let right = c.ray(200.0, 50.0).dir;
        assert!((right.angle_between(DVec3::NEG_Z) - 2f64.atan()).abs() < 1e-12);
        assert!(right.x > 0.0);
        assert!(c.ray(100.0, 50.0).dir.abs_diff_eq(DVec3::NEG_Z, 1e-15));
        assert!(Camera::perspective(DVec3::ZERO, DVec3::Y, DVec3::Y, 45.0, 1, 1).is_err());
        assert!(Camera::perspective(DVec3::ZERO, DVec3::X, DVec3::Y, 180.0, 1, 1).is_err());
    }
}
