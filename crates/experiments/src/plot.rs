//! Plots people would rather look at than numbers: false-colour maps with a colour bar (log
//! scale for beam exitance maps, diverging for differences) and log–log error-against-time
//! curves. PNG through plotters' bitmap backend with the DejaVu Sans font embedded from the
//! `dejavu` crate (so plots render on machines without system fonts), plus an SVG beside
//! every curve plot. Files are written atomically.

use std::path::Path;
use std::sync::Once;

use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use plotters::style::FontStyle;

use tracer::error::OutputError;
use tracer::output::write_atomic;

/// A plotting failure (drawing or encoding), or the output write.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// Drawing failed.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The plot's path.
        path: std::path::PathBuf,
        /// What plotters said.
        message: String,
    },
    /// Writing the file failed.
    #[error(transparent)]
    Output(#[from] OutputError),
}

fn draw_err(path: &Path, e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

static FONTS: Once = Once::new();

/// Registers the embedded font under "sans-serif" (once per process).
fn register_fonts() {
    FONTS.call_once(|| {
        // Registration only fails for unparsable font data; the embedded font is valid.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// How map values are turned into colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MapScale {
    /// log10 of positive values between `min` and `max` (non-positive values are drawn black).
    Log {
        /// Value at the bottom of the colour bar.
        min: f64,
        /// Value at the top.
        max: f64,
    },
    /// Signed values in `[-limit, limit]`, blue–white–red.
    Diverging {
        /// Magnitude at the ends of the colour bar.
        limit: f64,
    },
}

impl MapScale {
    /// A log scale spanning the positive values of `values`, clipped to `decades` below the max.
    pub fn log_for(values: &[f64], decades: f64) -> MapScale {
        let r = crate::colour_range::ColourRange::spanning(values, decades);
        MapScale::Log {
            min: r.min,
            max: r.max,
        }
    }

    /// Position of `v` on the colour bar, in [0, 1]; `None` for values the scale cannot show.
    fn position(&self, v: f64) -> Option<f64> {
        match *self {
            MapScale::Log { min, max } => (v > 0.0 && v.is_finite())
                .then(|| ((v.log10() - min.log10()) / (max.log10() - min.log10())).clamp(0.0, 1.0)),
            MapScale::Diverging { limit } => v
                .is_finite()
                .then(|| (0.5 + 0.5 * v / limit).clamp(0.0, 1.0)),
        }
    }

    fn colour(&self, t: f64) -> RGBColor {
        match self {
            MapScale::Log { .. } => viridis(t),
            MapScale::Diverging { .. } => diverging(t),
        }
    }

    fn value_at(&self, t: f64) -> f64 {
        match *self {
            MapScale::Log { min, max } => 10f64.powf(min.log10() + t * (max.log10() - min.log10())),
            MapScale::Diverging { limit } => (2.0 * t - 1.0) * limit,
        }
    }
}

/// A short viridis-like ramp (perceptually ordered, readable in grey).
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    lerp_stops(&STOPS, t)
}

fn diverging(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 3] = [
        (0.0, [33.0, 102.0, 172.0]),
        (0.5, [247.0, 247.0, 247.0]),
        (1.0, [178.0, 24.0, 43.0]),
    ];
    lerp_stops(&STOPS, t)
}

fn lerp_stops(stops: &[(f64, [f64; 3])], t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let k = stops
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(stops.len() - 2);
    let (t0, c0) = stops[k];
    let (t1, c1) = stops[k + 1];
    let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    let c = |i: usize| (c0[i] + f * (c1[i] - c0[i])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

fn encode_png(path: &Path, buf: Vec<u8>, w: u32, h: u32) -> Result<(), PlotError> {
    write_atomic(path, &png_of(path, buf, w, h)?)?;
    Ok(())
}

/// The PNG encoding of an RGB buffer (`path` is named in errors only).
fn png_of(path: &Path, buf: Vec<u8>, w: u32, h: u32) -> Result<Vec<u8>, PlotError> {
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| draw_err(path, "bad buffer"))?;
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| draw_err(path, e))?;
    Ok(bytes)
}

/// A false-colour map to plot.
#[derive(Debug, Clone, Copy)]
pub struct MapPlot<'a> {
    /// `width × height` values, row 0 at the top.
    pub values: &'a [f64],
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `[x0, x1, y0, y1]` shown on the axes.
    pub extent: [f64; 4],
    /// Colour scale.
    pub scale: MapScale,
    /// Title above the map.
    pub title: &'a str,
    /// Label of the colour bar.
    pub label: &'a str,
}

/// Writes a false-colour PNG of a map with a colour bar.
pub fn map_png(path: &Path, map: &MapPlot<'_>) -> Result<(), PlotError> {
    write_atomic(path, &map_png_bytes(path, map)?)?;
    Ok(())
}

/// The bytes [`map_png`] writes (`path` is named in errors only).
pub fn map_png_bytes(path: &Path, map: &MapPlot<'_>) -> Result<Vec<u8>, PlotError> {
    let MapPlot {
        values,
        width,
        height,
        extent,
        scale,
        title,
        label,
    } = *map;
    register_fonts();
    let cell = (480 / width.max(height)).max(1);
    let (pw, ph) = (width * cell, height * cell);
    let (w, h) = (pw + 90 + BAR_LABEL_AREA + 80, ph + 110);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(path, e))?;
        let (main, bar) = root.split_horizontally(pw + 90);
        let mut chart = ChartBuilder::on(&main)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(45)
            .build_cartesian_2d(extent[0]..extent[1], extent[2]..extent[3])
            .map_err(|e| draw_err(path, e))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_label_formatter(&|v| tick_label(*v))
            .y_label_formatter(&|v| tick_label(*v))
            .label_style(("sans-serif", LABEL_SIZE))
            .draw()
            .map_err(|e| draw_err(path, e))?;
        let dx = (extent[1] - extent[0]) / width as f64;
        let dy = (extent[3] - extent[2]) / height as f64;
        chart
            .draw_series(
                (0..height)
                    .flat_map(|i| (0..width).map(move |j| (i, j)))
                    .map(|(i, j)| {
                        let v = values[(i * width + j) as usize];
                        let colour = scale.position(v).map(|t| scale.colour(t)).unwrap_or(BLACK);
                        let x0 = extent[0] + j as f64 * dx;
                        let y1 = extent[3] - i as f64 * dy;
                        Rectangle::new([(x0, y1 - dy), (x0 + dx, y1)], colour.filled())
                    }),
            )
            .map_err(|e| draw_err(path, e))?;
        colour_bar(&bar, scale, label).map_err(|e| draw_err(path, e))?;
        root.present().map_err(|e| draw_err(path, e))?;
    }
    png_of(path, buf, w, h)
}

/// Font size (pixels) of tick labels and axis titles: legible at the PNGs' size.
const LABEL_SIZE: u32 = 15;

/// Width (pixels) left of a colour bar for its tick labels and its rotated title: the widest
/// tick label (`2.5×10⁻⁶`, about 65 pixels at [`LABEL_SIZE`]) plus the title's line, so that
/// the two do not overlap.
const BAR_LABEL_AREA: u32 = 110;

/// A tick label as people write numbers: `0.1`, `1`, `10`, `2.5`, `1500`; outside
/// `[0.001, 10⁵)` a power of ten (`10⁻⁶`) or a mantissa and one (`2.5×10⁻⁶`).
pub fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        // Three significant digits, trailing zeros dropped.
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        return if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
    }
    let e = a.log10().floor();
    let m = v / 10f64.powf(e);
    if (m.abs() - 1.0).abs() < 1e-9 {
        format!(
            "{}10{}",
            if v < 0.0 { "−" } else { "" },
            superscript(e as i32)
        )
    } else {
        format!("{}×10{}", tick_label(m), superscript(e as i32))
    }
}

/// The label of a colour-bar tick at `log10(value) = exponent`: `10⁻³` at whole decades,
/// otherwise the value itself ([`tick_label`]).
pub fn decade_label(exponent: f64) -> String {
    if (exponent - exponent.round()).abs() < 1e-9 {
        format!("10{}", superscript(exponent.round() as i32))
    } else {
        tick_label(10f64.powf(exponent))
    }
}

/// `n` in Unicode superscript digits (`−3` → `⁻³`).
fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(DIGITS[c as usize - '0' as usize]);
    }
    s
}

/// Tick positions for a logarithmic axis over `[lo, hi]` (0 < lo < hi): whole decades when
/// the range spans at least three, else 1-2-5 steps, else every mantissa 1…9, else tenths
/// of a decade's first digit, whichever first gives at least three ticks; at most twelve (every
/// second or fifth one kept beyond). A log axis then carries several labelled ticks however
/// narrow its range, where plotters' own key points on a range within one decade can be a
/// single `1`.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (e0, e1) = (lo.log10().floor() as i32 - 1, hi.log10().ceil() as i32 + 1);
        (e0..=e1)
            .flat_map(|e| mantissas.iter().map(move |m| m * 10f64.powi(e)))
            .filter(|v| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12))
            .collect()
    };
    let fine: Vec<f64> = (10..100).map(|k| k as f64 / 10.0).collect();
    let candidates: [&[f64]; 4] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
        &fine,
    ];
    for m in candidates {
        let ticks = within(m);
        if ticks.len() >= 3 {
            return thinned(ticks, 12);
        }
    }
    vec![lo, (lo * hi).sqrt(), hi]
}

/// Every k-th of `ticks` (k = 2 or 5, then larger) so that at most `most` remain.
fn thinned(ticks: Vec<f64>, most: usize) -> Vec<f64> {
    let mut k = 1;
    while ticks.len().div_ceil(k) > most {
        k = match k {
            1 => 2,
            2 => 5,
            _ => k * 2,
        };
    }
    ticks.into_iter().step_by(k).collect()
}

fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    scale: MapScale,
    label: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let log = matches!(scale, MapScale::Log { .. });
    let (lo, hi) = match scale {
        MapScale::Log { min, max } => (min.log10(), max.log10()),
        MapScale::Diverging { limit } => (-limit, limit),
    };
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(45)
        .margin_right(10)
        .y_label_area_size(BAR_LABEL_AREA)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_labels(6)
        .y_label_formatter(&|v| {
            if log {
                decade_label(*v)
            } else {
                tick_label(*v)
            }
        })
        .label_style(("sans-serif", LABEL_SIZE))
        .axis_desc_style(("sans-serif", LABEL_SIZE))
        .draw()?;
    let n = 200;
    chart.draw_series((0..n).map(|k| {
        let t0 = k as f64 / n as f64;
        let t1 = (k + 1) as f64 / n as f64;
        let y = |t: f64| {
            if log {
                scale.value_at(t).log10()
            } else {
                scale.value_at(t)
            }
        };
        Rectangle::new([(0.0, y(t0)), (1.0, y(t1))], scale.colour(t0).filled())
    }))?;
    Ok(())
}

/// One curve of a log–log plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// `(x, y)` points; non-positive values are skipped.
    pub points: Vec<(f64, f64)>,
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(228, 26, 28),
    RGBColor(55, 126, 184),
    RGBColor(77, 175, 74),
    RGBColor(152, 78, 163),
    RGBColor(255, 127, 0),
    RGBColor(166, 86, 40),
    RGBColor(247, 129, 191),
];

/// Writes a log–log plot of `series` to `png` and the same plot as SVG beside it (same name,
/// `.svg`).
pub fn loglog_png(
    png: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), PlotError> {
    register_fonts();
    let pts = || {
        series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| *x > 0.0 && *y > 0.0)
    };
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in pts() {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.1, 10.0, 0.1, 10.0);
    }
    let pad = |a: f64, b: f64| {
        if b > a * 1.0001 {
            (a / 1.3, b * 1.3)
        } else {
            (a / 2.0, a * 2.0)
        }
    };
    let (x0, x1) = pad(x0, x1);
    let (y0, y1) = pad(y0, y1);
    let (w, h) = (800u32, 560u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw_loglog(&root, title, x_label, y_label, series, (x0, x1, y0, y1))
            .map_err(|e| draw_err(png, e))?;
        root.present().map_err(|e| draw_err(png, e))?;
    }
    encode_png(png, buf, w, h)?;
    let svg_path = png.with_extension("svg");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        draw_loglog(&root, title, x_label, y_label, series, (x0, x1, y0, y1))
            .map_err(|e| draw_err(&svg_path, e))?;
        root.present().map_err(|e| draw_err(&svg_path, e))?;
    }
    write_atomic(&svg_path, svg.as_bytes())?;
    Ok(())
}

fn draw_loglog<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
            (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
        )?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style(("sans-serif", LABEL_SIZE))
        .axis_desc_style(("sans-serif", LABEL_SIZE))
        .draw()?;
    for (k, s) in series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|(x, y)| *x > 0.0 && *y > 0.0)
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, colour.filled())))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_read_as_people_write_numbers() {
        for (v, want) in [
            (0.1, "0.1"),
            (1.0, "1"),
            (10.0, "10"),
            (0.25, "0.25"),
            (2.5, "2.5"),
            (1500.0, "1500"),
            (0.001, "0.001"),
            (1e-6, "10⁻⁶"),
            (2.5e-6, "2.5×10⁻⁶"),
            (1e6, "10⁶"),
            (0.0, "0"),
        ] {
            assert_eq!(tick_label(v), want, "{v}");
        }
        assert_eq!(decade_label(-3.0), "10⁻³");
        assert_eq!(decade_label(0.0), "10⁰");
        assert_eq!(decade_label(12.0), "10¹²");
        assert_eq!(decade_label(-0.5), tick_label(10f64.powf(-0.5)));
    }

    #[test]
    fn plots_render_with_embedded_font() {
        let dir = tempfile::tempdir().unwrap();
        let map: Vec<f64> = (0..400).map(|k| (-(k as f64) / 40.0).exp()).collect();
        let p = dir.path().join("map.png");
        let plot = MapPlot {
            values: &map,
            width: 20,
            height: 20,
            extent: [-1.0, 1.0, -1.0, 1.0],
            scale: MapScale::log_for(&map, 4.0),
            title: "t",
            label: "v",
        };
        map_png(&p, &plot).unwrap();
        let img = image::open(&p).unwrap().to_rgb8();
        assert!(img.width() > 20 && img.height() > 20);
        // Not blank: many distinct colours.
        let distinct: std::collections::HashSet<_> = img.pixels().map(|p| p.0).collect();
        assert!(distinct.len() > 20);
        let q = dir.path().join("curves.png");
        let s = vec![
            Series {
                label: "a".into(),
                points: vec![(1.0, 1.0), (2.0, 0.5), (4.0, 0.25)],
            },
            Series {
                label: "b".into(),
                points: vec![(1.0, 0.3), (10.0, 0.3)],
            },
        ];
        loglog_png(&q, "err", "seconds", "rel. L2", &s).unwrap();
        assert!(q.exists() && dir.path().join("curves.svg").exists());
        let svg = std::fs::read_to_string(dir.path().join("curves.svg")).unwrap();
        assert!(svg.contains("seconds"));
    }

    #[test]
    fn log_scale_clips_to_decades() {
        let s = MapScale::log_for(&[1e-12, 1.0, 0.0, f64::NAN], 6.0);
        assert_eq!(
            s,
            MapScale::Log {
                min: 1e-6,
                max: 1.0
            }
        );
        assert_eq!(s.position(1.0), Some(1.0));
        assert_eq!(s.position(0.0), None);
    }

    /// Every log axis carries at least three labelled ticks and at most twelve, inside its
    /// range and increasing, from a factor of 1.3 (the convergence plot that showed one tick,
    /// `1`) to twelve decades; a curve plot's SVG shows them.
    #[test]
    fn log_axes_carry_several_ticks() {
        for (lo, hi) in [
            (0.77, 1.3),
            (0.19, 1.3),
            (0.4, 2.0),
            (1.0, 1.3),
            (0.05, 0.08),
            (1e-3, 10.0),
            (3e-7, 2e5),
        ] {
            let t = log_ticks(lo, hi);
            assert!((3..=12).contains(&t.len()), "[{lo}, {hi}]: {t:?}");
            assert!(t.windows(2).all(|w| w[0] < w[1]), "{t:?}");
            assert!(
                t.iter().all(|&v| v >= lo * 0.999 && v <= hi * 1.001),
                "{t:?}"
            );
        }
        assert_eq!(log_ticks(0.77, 1.3), vec![0.8, 0.9, 1.0]);
        assert!(log_ticks(-1.0, 1.0).is_empty());
        let dir = tempfile::tempdir().unwrap();
        let q = dir.path().join("narrow.png");
        let s = vec![Series {
            label: "a".into(),
            points: vec![(1.0, 0.9), (2.0, 0.7), (4.0, 0.6)],
        }];
        loglog_png(&q, "err", "seconds", "rel. L2", &s).unwrap();
        let svg = std::fs::read_to_string(q.with_extension("svg")).unwrap();
        for label in ["0.5", "0.6", "0.8", "1"] {
            let text = format!(">\n{label}\n</text>");
            assert!(svg.contains(&text), "no tick {label} in the SVG: {svg}");
        }
    }
}
