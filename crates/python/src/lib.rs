//! Python bindings of het-bssrdf (module `het_bssrdf`, built with maturin as an abi3 wheel):
//!
//! * [`Profile`]: a radial profile family R(r) (1/length²) evaluated on numpy arrays of radii;
//! * [`Bssrdf`]: the full separable S (`bssrdf_core::SeparableBssrdf`) on pairs of
//!   [`Crossings`] (arrays of point, normal and direction triples);
//! * [`Field`] and `Estimator` ([`PyEstimator`]): the estimators (`het_estimate::Estimator`) on
//!   arrays of point pairs over the built-in analytic plane z = 0 and its fields (constant,
//!   stripes, checks);
//! * [`render`]: a scene file rendered by the tracer to an (height, width, 3) numpy array.
//!
//! Errors are Python exceptions: `ValueError` for invalid parameters (the message names the
//! parameter, as the Rust crates' `ParamError` does), `OSError`/`ValueError` for scene files.
//! Long calls release the GIL.

use numpy::ndarray::{Array1, Array2, ArrayView2, Axis};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

use het_estimate::analytic::{CheckField, ConstantField, Plane, PlanePoint, StripeField};
use het_estimate::bssrdf_core::glam::DVec3;
use het_estimate::bssrdf_core::{
    Coefficients, Crossing, ParamError, ProfileFamily, ProfileModel, RadialProfile, Rgb,
    Scattering, SeparableBssrdf,
};
use het_estimate::pattern::{Check, Stripe};
use het_estimate::{Estimator, PreparedEstimator, SplitMix64};

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn parse<T: std::str::FromStr>(s: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    s.parse::<T>().map_err(value_error)
}

/// An (N, 3) array as rows, or a `ValueError` naming `what`.
fn rows3(a: &ArrayView2<'_, f64>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    if a.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "`{what}` must have shape (N, 3), got {:?}",
            a.shape()
        )));
    }
    Ok(a.axis_iter(Axis(0)).map(|r| [r[0], r[1], r[2]]).collect())
}

/// Three channel values from a sequence of 1 or 3 floats.
fn channels(v: &[f64], what: &str) -> PyResult<Rgb> {
    match *v {
        [x] => Ok(Rgb::splat(x)),
        [r, g, b] => Ok(Rgb::new(r, g, b)),
        _ => Err(PyValueError::new_err(format!(
            "`{what}` must hold 1 or 3 values, got {}",
            v.len()
        ))),
    }
}

/// A radial profile family: `Profile(model="pbd", scattering="multiple", g=0.0, eta=1.3)`.
///
/// `model` is one of `dipole`, `pbd`, `better-dipole`, `tabulated`;
/// `scattering` one of `single`, `multiple`, `all`; `g` the Henyey–Greenstein mean cosine
/// (|g| < 1); `eta` the relative index of refraction (1 to 3, at most 1.6 for `tabulated`).
#[pyclass(frozen, module = "het_bssrdf")]
struct Profile {
    family: ProfileFamily,
}

#[pymethods]
impl Profile {
    #[new]
    #[pyo3(signature = (model = "pbd", scattering = "multiple", g = 0.0, eta = 1.3))]
    fn new(model: &str, scattering: &str, g: f64, eta: f64) -> PyResult<Self> {
        let family =
            ProfileFamily::new(parse(model)?, parse(scattering)?, g, eta).map_err(value_error)?;
        Ok(Self { family })
    }

    /// R(r) (1/length², the exitance per unit incident power, no Fresnel factor and no
    /// angular normalisation) at every radius of the 1-D array `r`, for coefficients
    /// `sigma_a`, `sigma_s` (1/length, in [0, 1e12]).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        r: PyReadonlyArray1<'py, f64>,
        sigma_a: f64,
        sigma_s: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let profile = self.family.profile(sigma_a, sigma_s).map_err(value_error)?;
        let radii = r.as_array();
        if let Some(bad) = radii.iter().find(|x| !(**x >= 0.0 && x.is_finite())) {
            return Err(value_error(ParamError::Negative {
                name: "r",
                value: *bad,
            }));
        }
        Ok(radii.mapv(|x| profile.eval(x)).into_pyarray(py))
    }

    /// The total diffuse reflectance ∫ 2πr R(r) dr (dimensionless).
    fn total(&self, sigma_a: f64, sigma_s: f64) -> PyResult<f64> {
        Ok(self
            .family
            .profile(sigma_a, sigma_s)
            .map_err(value_error)?
            .total())
    }

    fn __repr__(&self) -> String {
        format!(
            "Profile(model='{}', scattering='{}', g={}, eta={})",
            self.family.model(),
            self.family.scattering(),
            self.family.g(),
            self.family.eta()
        )
    }
}

/// N places where light crosses the boundary: `Crossings(x, n, w)`, each an (N, 3) array of
/// points `x`, their unit normals `n` out of the medium and unit directions `w` outside,
/// pointing away from the surface (toward the light where light enters, toward the viewer
/// where it leaves). One end of N pairs for [`Bssrdf::eval`] (in Rust, N
/// `bssrdf_core::Crossing`s).
#[pyclass(frozen, module = "het_bssrdf")]
struct Crossings {
    rows: Vec<Crossing>,
}

#[pymethods]
impl Crossings {
    #[new]
    fn new(
        x: PyReadonlyArray2<'_, f64>,
        n: PyReadonlyArray2<'_, f64>,
        w: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Self> {
        let (x, n, w) = (
            rows3(&x.as_array(), "x")?,
            rows3(&n.as_array(), "n")?,
            rows3(&w.as_array(), "w")?,
        );
        if n.len() != x.len() || w.len() != x.len() {
            return Err(PyValueError::new_err(format!(
                "x, n and w must hold the same number of rows, got {}, {} and {}",
                x.len(),
                n.len(),
                w.len()
            )));
        }
        let v = DVec3::from_array;
        let rows = (0..x.len())
            .map(|i| Crossing::new(v(x[i]), v(n[i]), v(w[i])))
            .collect();
        Ok(Self { rows })
    }

    fn __len__(&self) -> usize {
        self.rows.len()
    }

    fn __repr__(&self) -> String {
        format!("Crossings(<{} rows>)", self.rows.len())
    }
}

/// The separable BSSRDF S(x_i, ω_i; x_o, ω_o) the `het-bssrdf` renderer uses:
/// `Bssrdf(model="tabulated", scattering="all", g=0.0, eta=1.3, angular_coupling=True)`.
///
/// S = R(|x_i − x_o|) (1 − F_r(cos θ_i))(1 − F_r(cos θ_o)) / (c π) · T, with
/// c = 1 − 2 C₁(1/η) and T the tabulated profile's angular coupling (1 for other models).
#[pyclass(frozen, module = "het_bssrdf")]
struct Bssrdf {
    bssrdf: SeparableBssrdf,
}

#[pymethods]
impl Bssrdf {
    #[new]
    #[pyo3(signature = (model = "tabulated", scattering = "all", g = 0.0, eta = 1.3, angular_coupling = true))]
    fn new(
        model: &str,
        scattering: &str,
        g: f64,
        eta: f64,
        angular_coupling: bool,
    ) -> PyResult<Self> {
        let bssrdf = SeparableBssrdf::new(parse(model)?, parse(scattering)?, g, eta)
            .map_err(value_error)?
            .with_angular_coupling(angular_coupling);
        Ok(Self { bssrdf })
    }

    /// The normalisation c = 1 − 2 C₁(1/η).
    #[getter]
    fn normalisation(&self) -> f64 {
        self.bssrdf.normalisation()
    }

    /// S per channel (1/(length²·sr)), an (N, 3) array, for the N pairs of `incident[k]`
    /// (where light enters: its direction points toward the light) and `exitant[k]` (where it
    /// leaves: toward the viewer), two [`Crossings`] of N rows; `sigma_a`, `sigma_s` the
    /// coefficients, (N, 3) arrays (per pair) or sequences of 1 or 3 values (every pair).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        sigma_a: &Bound<'py, PyAny>,
        sigma_s: &Bound<'py, PyAny>,
        incident: &Crossings,
        exitant: &Crossings,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = incident.rows.len();
        if exitant.rows.len() != n {
            return Err(PyValueError::new_err(format!(
                "incident has {n} rows and exitant {}",
                exitant.rows.len()
            )));
        }
        let sa = per_pair(sigma_a, n, "sigma_a")?;
        let ss = per_pair(sigma_s, n, "sigma_s")?;
        let mut out = Array2::<f64>::zeros((n, 3));
        for i in 0..n {
            let c = Coefficients::new(sa[i], ss[i]);
            let (incident, exitant) = (incident.rows[i], exitant.rows[i]);
            let s = self
                .bssrdf
                .eval(&c, &incident, &exitant)
                .map_err(|e| PyValueError::new_err(format!("pair {i}: {e}")))?;
            for ch in 0..3 {
                out[[i, ch]] = s[ch];
            }
        }
        Ok(out.into_pyarray(py))
    }
}

/// Coefficients for `n` pairs from an (n, 3) array or a sequence of 1 or 3 values.
fn per_pair(v: &Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<Vec<Rgb>> {
    if let Ok(a) = v.extract::<PyReadonlyArray2<'_, f64>>() {
        let rows = rows3(&a.as_array(), what)?;
        if rows.len() != n {
            return Err(PyValueError::new_err(format!(
                "`{what}` has {} rows for {n} pairs",
                rows.len()
            )));
        }
        return Ok(rows.into_iter().map(Rgb).collect());
    }
    let values: Vec<f64> = v.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "`{what}` must be an (N, 3) array or 1 or 3 numbers"
        ))
    })?;
    Ok(vec![channels(&values, what)?; n])
}

/// The built-in fields over the plane z = 0 (the medium below it), the surface `Estimator.estimate`
/// works on. Made by `Field.constant`, `Field.stripes` or `Field.checks`; coefficients are
/// sequences of 1 or 3 values (1/length).
#[pyclass(frozen, module = "het_bssrdf")]
#[derive(Clone, Copy)]
struct Field {
    kind: FieldKind,
}

#[derive(Clone, Copy)]
enum FieldKind {
    Constant(ConstantField),
    Stripes(StripeField),
    Checks(CheckField),
}

fn coefficients(sigma_a: &[f64], sigma_s: &[f64]) -> PyResult<Coefficients> {
    Coefficients::new(channels(sigma_a, "sigma_a")?, channels(sigma_s, "sigma_s")?)
        .validate()
        .map_err(value_error)
}

fn positive(name: &'static str, v: f64) -> PyResult<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(value_error(ParamError::OutOfRange {
            name,
            range: "(0, inf)",
            value: v,
        }))
    }
}

#[pymethods]
impl Field {
    /// The same coefficients everywhere.
    #[staticmethod]
    fn constant(sigma_a: Vec<f64>, sigma_s: Vec<f64>) -> PyResult<Self> {
        Ok(Self {
            kind: FieldKind::Constant(ConstantField(coefficients(&sigma_a, &sigma_s)?)),
        })
    }

    /// Stripes of width `width` varying along the direction at `angle` radians: `a` (a pair
    /// `(sigma_a, sigma_s)`) in the stripe holding the origin, `b` in the next.
    #[staticmethod]
    #[pyo3(signature = (width, a, b, angle = 0.0))]
    fn stripes(
        width: f64,
        a: (Vec<f64>, Vec<f64>),
        b: (Vec<f64>, Vec<f64>),
        angle: f64,
    ) -> PyResult<Self> {
        Ok(Self {
            kind: FieldKind::Stripes(StripeField {
                pattern: Stripe::new(positive("width", width)?, angle),
                values: [coefficients(&a.0, &a.1)?, coefficients(&b.0, &b.1)?],
            }),
        })
    }

    /// A checkerboard of cells `width` wide: `a` (a pair `(sigma_a, sigma_s)`) in the cell
    /// holding the origin, `b` in its neighbours.
    #[staticmethod]
    fn checks(width: f64, a: (Vec<f64>, Vec<f64>), b: (Vec<f64>, Vec<f64>)) -> PyResult<Self> {
        Ok(Self {
            kind: FieldKind::Checks(CheckField {
                pattern: Check {
                    width: positive("width", width)?,
                },
                values: [coefficients(&a.0, &a.1)?, coefficients(&b.0, &b.1)?],
            }),
        })
    }
}

/// Runs `prepared` on every pair of the field's plane, each pair with its own stream
/// (`seed` + the pair's index).
fn estimate_pairs<F: het_estimate::CoefficientField<PlanePoint>>(
    prepared: &PreparedEstimator,
    field: &F,
    pairs: &[(PlanePoint, PlanePoint)],
    seed: u64,
) -> Vec<Coefficients> {
    pairs
        .iter()
        .enumerate()
        .map(|(k, (x_i, x_o))| {
            let mut rng = SplitMix64::new(seed.wrapping_add(k as u64));
            prepared
                .estimate(&Plane, field, x_i, x_o, &mut rng)
                .coefficients
        })
        .collect()
}

/// An estimator prepared for a material: `Estimator(name, g=0.0, eta=1.3)`, `name` one of
/// `ESTIMATORS` (`jensen-in`, `jensen-out`, `endpoints`, `segment`, `sone`, `kernel`, with
/// default parameters), for a material with mean cosine `g` and relative index `eta` (in
/// Rust, `het_estimate::Estimator::prepare`).
#[pyclass(frozen, name = "Estimator", module = "het_bssrdf")]
struct PyEstimator {
    prepared: PreparedEstimator,
    g: f64,
    eta: f64,
}

#[pymethods]
impl PyEstimator {
    #[new]
    #[pyo3(signature = (name, g = 0.0, eta = 1.3))]
    fn new(name: &str, g: f64, eta: f64) -> PyResult<Self> {
        let prepared = parse::<Estimator>(name)?
            .prepare(g, eta)
            .map_err(value_error)?;
        Ok(Self { prepared, g, eta })
    }

    /// The homogeneous coefficients this estimator chooses for N pairs of points on the plane
    /// z = 0 over `field`: `x_i` and `x_o` are (N, 2) arrays of (x, y); returns
    /// `(sigma_a, sigma_s)`, two (N, 3) arrays. Pair k draws its random numbers from
    /// `seed + k`, so results do not depend on how the pairs are batched.
    #[pyo3(signature = (field, x_i, x_o, seed = 0))]
    #[allow(clippy::type_complexity)]
    fn estimate<'py>(
        &self,
        py: Python<'py>,
        field: &Field,
        x_i: PyReadonlyArray2<'py, f64>,
        x_o: PyReadonlyArray2<'py, f64>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let prepared = &self.prepared;
        let points = |a: &ArrayView2<'_, f64>, what: &str| -> PyResult<Vec<PlanePoint>> {
            if a.ncols() != 2 {
                return Err(PyValueError::new_err(format!(
                    "`{what}` must have shape (N, 2), got {:?}",
                    a.shape()
                )));
            }
            Ok(a.axis_iter(Axis(0))
                .map(|r| PlanePoint::new(r[0], r[1]))
                .collect())
        };
        let (pi, po) = (
            points(&x_i.as_array(), "x_i")?,
            points(&x_o.as_array(), "x_o")?,
        );
        if pi.len() != po.len() {
            return Err(PyValueError::new_err(format!(
                "x_i has {} rows and x_o {}",
                pi.len(),
                po.len()
            )));
        }
        let pairs: Vec<_> = pi.into_iter().zip(po).collect();
        let kind = field.kind;
        let result = py.detach(|| match &kind {
            FieldKind::Constant(f) => estimate_pairs(prepared, f, &pairs, seed),
            FieldKind::Stripes(f) => estimate_pairs(prepared, f, &pairs, seed),
            FieldKind::Checks(f) => estimate_pairs(prepared, f, &pairs, seed),
        });
        let mut sa = Array2::<f64>::zeros((result.len(), 3));
        let mut ss = Array2::<f64>::zeros((result.len(), 3));
        for (k, c) in result.iter().enumerate() {
            for ch in 0..3 {
                sa[[k, ch]] = c.sigma_a[ch];
                ss[[k, ch]] = c.sigma_s[ch];
            }
        }
        Ok((sa.into_pyarray(py), ss.into_pyarray(py)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Estimator('{}', g={}, eta={})",
            self.prepared.estimator(),
            self.g,
            self.eta
        )
    }
}

/// Renders the scene file `scene_path` with `method` (`pt` for the path-traced reference,
/// `auto`, or an estimator name for the BSSRDF renderer) at `spp` samples per pixel (the
/// scene's own when `None`) and `seed` (the scene's own when `None`), on all cores. Returns
/// the mean radiance per pixel as a float64 array of shape (height, width, 3), row 0 at the
/// top. Deterministic for a seed, whatever the thread count.
#[pyfunction]
#[pyo3(signature = (scene_path, method = "auto", spp = None, seed = None))]
fn render<'py>(
    py: Python<'py>,
    scene_path: std::path::PathBuf,
    method: &str,
    spp: Option<u32>,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    use tracer::integrator::{Method, PathIntegrator, PathOptions};
    use tracer::render::RenderOptions;
    use tracer::scene::Scene;

    let method: Method = parse(method)?;
    if spp == Some(0) {
        return Err(PyValueError::new_err("spp must be at least 1"));
    }
    let (width, height, pixels) = py.detach(|| -> PyResult<_> {
        let scene = Scene::load(&scene_path).map_err(|e| match &e {
            tracer::error::SceneError::Io { .. } => PyOSError::new_err(e.to_string()),
            _ => value_error(&e),
        })?;
        let settings = scene.settings();
        let options = PathOptions {
            scattering: settings.scattering.unwrap_or_default(),
            // The command line's default depth.
            max_depth: settings.max_depth.unwrap_or(8),
        };
        let integrator = PathIntegrator::new(&scene, method, options).map_err(value_error)?;
        let (w, h) = scene.camera().resolution();
        let rendered = tracer::render::render(
            w,
            h,
            &integrator,
            &RenderOptions::samples(spp.unwrap_or(settings.spp), seed.unwrap_or(settings.seed)),
        );
        Ok((w as usize, h as usize, rendered.pixels))
    })?;
    let flat: Array1<f64> = pixels.iter().flat_map(|p| p.0).collect();
    let image = flat
        .into_shape_with_order((height, width, 3))
        .map_err(value_error)?;
    Ok(image.into_pyarray(py))
}

/// The module `het_bssrdf`.
#[pymodule]
fn het_bssrdf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "PROFILE_MODELS",
        ProfileModel::ALL
            .iter()
            .map(|m| m.to_string())
            .collect::<Vec<_>>(),
    )?;
    m.add(
        "SCATTERING",
        Scattering::ALL
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>(),
    )?;
    m.add(
        "ESTIMATORS",
        Estimator::ALL
            .iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>(),
    )?;
    m.add_class::<Profile>()?;
    m.add_class::<Bssrdf>()?;
    m.add_class::<Crossings>()?;
    m.add_class::<Field>()?;
    m.add_class::<PyEstimator>()?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    Ok(())
}
