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

/// How a point is seen by the camera, for light tracing ([`Camera::connect`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraConnection {
    /// Film position (pixels, see the module docs) of the camera ray through the point.
    pub film: (f64, f64),
    /// Pixel `(x, y)` holding [`CameraConnection::film`].
    pub pixel: (u32, u32),
    /// Unit direction from the point toward the camera (the camera ray reversed).
    pub to_camera: DVec3,
    /// Distance from the point to the eye (perspective) or to the view plane
    /// (orthographic) along `to_camera`: a visibility segment is this long.
    pub dist: f64,
    /// The importance of the point for its pixel per unit surface area and unit projected
    /// cosine (1/length²): radiance `L` leaving an area `dA` at the point toward the camera,
    /// with cosine `cos θ` between `to_camera` and the surface's geometric normal, adds
    /// `importance · cos θ · L · dA` to the pixel's value (the mean radiance over the pixel,
    /// as [`crate::render`] computes it). Perspective: `1/(A_p cos³θ_c d²)`, with `A_p` the
    /// pixel's area on the image plane at distance 1 and `θ_c` the angle between the ray and
    /// the view direction (pbrt3 §16.1.1 and pbrt-v4's `PerspectiveCamera::We`, for one pixel
    /// instead of the whole film); orthographic: `1/A_p` with `A_p` the pixel's area on the
    /// view plane.
    pub importance: f64,
}

impl Camera {
    /// The pixel through which the camera sees the point `p`, and its importance (see
    /// [`CameraConnection`]); `None` when `p` is outside the film, behind the eye or behind
    /// the orthographic view plane. Visibility is the caller's (a segment of length
    /// [`CameraConnection::dist`] from `p` along [`CameraConnection::to_camera`]).
    pub fn connect(&self, p: DVec3) -> Option<CameraConnection> {
        let (w, h) = self.resolution();
        let (w, h) = (w as f64, h as f64);
        let (film, to_camera, dist, importance) = match self {
            Camera::Perspective(c) => {
                let d = p - c.eye;
                let dist = d.length();
                if !(dist > 0.0 && dist.is_finite()) {
                    return None;
                }
                let dir = d / dist;
                let cos = dir.dot(c.frame.forward);
                if cos <= 0.0 {
                    return None;
                }
                let sx = dir.dot(c.frame.right) / cos;
                let sy = dir.dot(c.frame.up) / cos;
                let film = (
                    (sx / (c.tan_half_fov_y * (w / h)) + 1.0) * 0.5 * w,
                    (1.0 - sy / c.tan_half_fov_y) * 0.5 * h,
                );
                let side = 2.0 * c.tan_half_fov_y / h;
                let importance = 1.0 / (side * side * cos * cos * cos * dist * dist);
                (film, -dir, dist, importance)
            }
            Camera::Orthographic(c) => {
                let rel = p - c.centre;
                let dist = rel.dot(c.frame.forward);
                if !(dist > 0.0 && dist.is_finite()) {
                    return None;
                }
                let film = (
                    (rel.dot(c.frame.right) / c.view_width + 0.5) * w,
                    (0.5 - rel.dot(c.frame.up) / c.view_height) * h,
                );
                let area = (c.view_width / w) * (c.view_height / h);
                (film, -c.frame.forward, dist, 1.0 / area)
            }
        };
        if !(film.0 >= 0.0 && film.0 < w && film.1 >= 0.0 && film.1 < h) {
            return None;
        }
        let pixel = (
            (film.0 as u32).min(w as u32 - 1),
            (film.1 as u32).min(h as u32 - 1),
        );
        Some(CameraConnection {
            film,
            pixel,
            to_camera,
            dist,
            importance,
        })
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

    /// `connect` inverts `ray`: the point a film position's ray reaches maps back to that
    /// film position, and the direction to the camera is the ray's reversed.
    #[test]
    fn connect_inverts_the_camera_ray() {
        let cams = [
            Camera::perspective(
                DVec3::new(0.3, -2.0, 4.0),
                DVec3::ZERO,
                DVec3::Z,
                50.0,
                40,
                30,
            )
            .unwrap(),
            Camera::orthographic(
                DVec3::new(0.0, 0.0, 5.0),
                DVec3::new(0.2, 0.1, -1.0),
                DVec3::Y,
                6.0,
                4.0,
                30,
                20,
            )
            .unwrap(),
        ];
        for cam in cams {
            let (w, h) = cam.resolution();
            for (fx, fy) in [(0.25, 0.5), (13.7, 9.2), (w as f64 - 0.01, h as f64 - 0.01)] {
                let ray = cam.ray(fx, fy);
                let p = ray.origin + 3.5 * ray.dir;
                let c = cam.connect(p).unwrap();
                assert!((c.film.0 - fx).abs() < 1e-9 && (c.film.1 - fy).abs() < 1e-9);
                assert_eq!(c.pixel, (fx as u32, fy as u32));
                assert!(c.to_camera.abs_diff_eq(-ray.dir, 1e-12));
                assert!((c.dist - 3.5).abs() < 1e-9);
                assert!(c.importance > 0.0 && c.importance.is_finite());
            }
            // Behind the camera.
            let ray = cam.ray(1.0, 1.0);
            assert!(cam.connect(ray.origin - ray.dir).is_none());
        }
    }

    /// The perspective importance integrates to 1 over a pixel's footprint: on a plane
    /// facing the camera, Σ importance · cos · dA over a fine grid of the plane that lands
    /// in one pixel is 1 (the pixel's value is the mean radiance over it).
    #[test]
    fn perspective_importance_integrates_to_one_per_pixel() {
        let cam = Camera::perspective(DVec3::ZERO, DVec3::NEG_Z, DVec3::Y, 60.0, 8, 6).unwrap();
        // A plane z = -2 tilted: normal n, points p = base + u·a + v·b.
        let n = DVec3::new(0.3, 0.2, 1.0).normalize();
        let (a, b) = orthonormal(n);
        let base = DVec3::new(0.0, 0.0, -2.0);
        let (m, half) = (1500, 2.5);
        let step = 2.0 * half / m as f64;
        let mut sums = [0.0f64; 48];
        for i in 0..m {
            for j in 0..m {
                let u = -half + (i as f64 + 0.5) * step;
                let v = -half + (j as f64 + 0.5) * step;
                let p = base + u * a + v * b;
                if let Some(c) = cam.connect(p) {
                    let cos = c.to_camera.dot(n).abs();
                    sums[(c.pixel.1 * 8 + c.pixel.0) as usize] += c.importance * cos * step * step;
                }
            }
        }
        for (k, s) in sums.iter().enumerate() {
            assert!((s - 1.0).abs() < 5e-3, "pixel {k}: {s}");
        }
    }

    fn orthonormal(n: DVec3) -> (DVec3, DVec3) {
        let a = n.cross(DVec3::X).normalize();
        (a, n.cross(a))
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
