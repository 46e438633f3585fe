#![doc = include_str!("../README.md")]

use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

mod heat;
mod line;

/// Errors while drawing or saving a chart.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The image size is zero or too large (each side must be in [64, 16384] px).
    #[error("image size {width}x{height} px outside [64, 16384] px per side")]
    Size {
        /// Requested width, px.
        width: u32,
        /// Requested height, px.
        height: u32,
    },
    /// Nothing to draw.
    #[error("no panels to draw")]
    NoPanels,
    /// A heat map whose value count does not match its grid.
    #[error("heat map '{title}': {len} values for a {nx}x{ny} grid")]
    HeatMapShape {
        /// Panel title.
        title: String,
        /// Number of values given.
        len: usize,
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
    },
    /// A failure inside plotters (drawing or font).
    #[error("drawing failed: {0}")]
    Draw(String),
    /// PNG encoding failed.
    #[error("PNG encoding failed: {0}")]
    Encode(#[from] image::ImageError),
    /// Writing the file failed.
    #[error("writing the chart failed: {0}")]
    Io(#[from] std::io::Error),
    /// The chart could not be written whole (see [`skin_io::atomic`]).
    #[error(transparent)]
    Write(#[from] skin_io::atomic::AtomicWriteError),
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// Solid polyline.
    #[default]
    Line,
    /// Dashed polyline.
    Dashed,
    /// Filled circles, no line (scatter).
    Points,
    /// Solid polyline with a circle at every point.
    LinePoints,
}

/// One named curve of a [`LineChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry (empty: no legend entry).
    pub name: String,
    /// Data points (x, y) in the chart's units; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line, dashed line or scatter.
    pub style: SeriesStyle,
    /// Explicit colour (8-bit sRGB); `None` takes the palette colour of the series' index.
    pub color: Option<[u8; 3]>,
}

impl Series {
    /// A solid line.
    #[must_use]
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            style: SeriesStyle::Line,
            color: None,
        }
    }

    /// A dashed line.
    #[must_use]
    pub fn dashed(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            style: SeriesStyle::Dashed,
            ..Self::line(name, points)
        }
    }

    /// A scatter of points.
    #[must_use]
    pub fn scatter(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            style: SeriesStyle::Points,
            ..Self::line(name, points)
        }
    }

    /// The same series in another style.
    #[must_use]
    pub fn with_style(mut self, style: SeriesStyle) -> Self {
        self.style = style;
        self
    }

    /// The same series in an explicit colour (8-bit sRGB).
    #[must_use]
    pub fn with_color(mut self, rgb: [u8; 3]) -> Self {
        self.color = Some(rgb);
        self
    }
}

/// A 2D chart of named series with optional log axes and a legend.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LineChart {
    /// Title above the panel.
    pub title: String,
    /// x axis label (with unit).
    pub x_label: String,
    /// y axis label (with unit).
    pub y_label: String,
    /// Logarithmic x axis (points with x ≤ 0 are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (points with y ≤ 0 are dropped).
    pub log_y: bool,
    /// Fixed x range; `None` fits the data.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range; `None` fits the data.
    pub y_range: Option<(f64, f64)>,
    /// The curves, drawn in order.
    pub series: Vec<Series>,
}

impl LineChart {
    /// An empty chart with a title and axis labels.
    #[must_use]
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            ..Self::default()
        }
    }

    /// Use a logarithmic x axis.
    #[must_use]
    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }

    /// Use a logarithmic y axis.
    #[must_use]
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// Fix the x range instead of fitting the data.
    #[must_use]
    pub fn with_x_range(mut self, min: f64, max: f64) -> Self {
        self.x_range = Some((min, max));
        self
    }

    /// Fix the y range instead of fitting the data.
    #[must_use]
    pub fn with_y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }

    /// Add a series.
    #[must_use]
    pub fn with_series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }
}

/// A grid of values shown as coloured cells with a colour bar (viridis), e.g. a stability map.
///
/// Cell (i, j) covers the i-th of `nx` equal steps of `x_range` and the j-th of `ny` steps of
/// `y_range` (equal in log space on a log axis); its value is `values[j * nx + i]`.
/// Non-finite values are drawn grey (e.g. "undefined" regions).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeatMap {
    /// Title above the panel.
    pub title: String,
    /// x axis label (with unit).
    pub x_label: String,
    /// y axis label (with unit).
    pub y_label: String,
    /// Colour bar label (with unit).
    pub value_label: String,
    /// x extent of the grid (cell edges).
    pub x_range: (f64, f64),
    /// y extent of the grid (cell edges).
    pub y_range: (f64, f64),
    /// Logarithmic x axis (cells equal in log x; the range must be positive).
    pub log_x: bool,
    /// Logarithmic y axis (cells equal in log y; the range must be positive).
    pub log_y: bool,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Row-major values, `ny` rows of `nx`, row 0 at the low end of `y_range`.
    pub values: Vec<f64>,
    /// Fixed colour scale; `None` spans the finite values.
    pub value_range: Option<(f64, f64)>,
    /// Scatter drawn over the cells (e.g. sample points, a boundary), in axis units.
    pub overlay: Vec<Series>,
}

/// One panel of a figure.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Lines and/or scatter.
    Line(LineChart),
    /// Coloured grid with a colour bar.
    Heat(HeatMap),
}

/// Tableau-10: distinguishable colours for consecutive series.
const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// The palette colour of series `i` (8-bit sRGB), for callers that want matching colours elsewhere.
#[must_use]
pub fn palette_color(i: usize) -> [u8; 3] {
    PALETTE[i % PALETTE.len()]
}

fn register_bundled_font() -> Result<(), PlotError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../assets/fonts/DejaVuSans.ttf"),
        )
        .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Draw(
            "bundled DejaVuSans.ttf is not a valid font".into(),
        ))
    }
}

fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// Render the panels, stacked vertically, into an 8-bit RGB buffer of `width × height` pixels.
pub fn render_rgb(panels: &[Panel], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    if !(64..=16384).contains(&width) || !(64..=16384).contains(&height) {
        return Err(PlotError::Size { width, height });
    }
    if panels.is_empty() {
        return Err(PlotError::NoPanels);
    }
    for p in panels {
        if let Panel::Heat(h) = p
            && h.values.len() != h.nx * h.ny
        {
            return Err(PlotError::HeatMapShape {
                title: h.title.clone(),
                len: h.values.len(),
                nx: h.nx,
                ny: h.ny,
            });
        }
    }
    register_bundled_font()?;
    let mut buf = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let areas = root.split_evenly((panels.len(), 1));
        for (panel, area) in panels.iter().zip(&areas) {
            match panel {
                Panel::Line(c) => line::draw_line_panel(area, c)?,
                Panel::Heat(h) => heat::draw_heat_panel(area, h)?,
            }
        }
        root.present().map_err(draw_err)?;
    }
    Ok(buf)
}

/// Render the panels (stacked vertically) and save them as a PNG of `width × height` pixels,
/// atomically ([`skin_io::atomic`]: unique temporary file, then rename).
pub fn save_png(path: &Path, panels: &[Panel], width: u32, height: u32) -> Result<(), PlotError> {
    let buf = render_rgb(panels, width, height)?;
    // The buffer was allocated as width × height × 3 bytes above, so `from_raw` cannot fail.
    let img = image::RgbImage::from_raw(width, height, buf)
        .ok_or_else(|| PlotError::Draw("buffer size mismatch".into()))?;
    skin_io::atomic::write_via_temp(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(PlotError::from)
    })
}

/// Fit an axis range to `values`: padded 5% on a linear axis, widened to whole decades on a log
/// axis; degenerate or empty ranges get a sensible width.
fn fit_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        // Whole decades: plotters labels a log axis at powers of ten only, so a range inside one
        // decade would show a single tick.
        let lo_d = lo.log10().floor();
        let hi_d = hi.log10().ceil().max(lo_d + 1.0);
        (10f64.powf(lo_d), 10f64.powf(hi_d))
    } else {
        let span = hi - lo;
        let pad = if span <= 1e-12 * lo.abs().max(hi.abs()) || span == 0.0 {
            if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() }
        } else {
            0.05 * span
        };
        (lo - pad, hi + pad)
    }
}

/// A user-given range made drawable: kept exactly when finite, ordered, non-empty (and positive on
/// a log axis), else replaced by a padded fit of its ends.
fn sanitize_range(r: (f64, f64), log: bool) -> (f64, f64) {
    let (a, b) = (r.0.min(r.1), r.0.max(r.1));
    if a.is_finite() && b.is_finite() && b > a && (!log || a > 0.0) {
        (a, b)
    } else {
        fit_range([r.0, r.1].into_iter(), log)
    }
}

fn usable(p: (f64, f64), log_x: bool, log_y: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_x || p.0 > 0.0) && (!log_y || p.1 > 0.0)
}

/// Tick label: short, without trailing noise ("0.001", "250", "1e-5").
fn tick_label(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.0e}");
        if s.parse::<f64>().is_ok_and(|p| (p - v).abs() <= 1e-9 * a) {
            s
        } else {
            format!("{v:.1e}")
        }
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("skin-plot-{tag}-{}", std::process::id()))
    }

    fn sample_panels() -> Vec<Panel> {
        let curve: Vec<(f64, f64)> = (0..=30)
            .map(|i| {
                let nm = 400.0 + 10.0 * f64::from(i);
                (nm, 6.6e10 * nm.powf(-3.33))
            })
            .collect();
        // Non-finite and non-positive points must be skipped, not break the chart.
        let mut messy = curve.clone();
        messy[3].1 = f64::NAN;
        messy[7].1 = -1.0;
        messy[9].0 = f64::INFINITY;
        let lines = LineChart::new("absorption", "wavelength (nm)", "σa (mm⁻¹)")
            .log_y()
            .with_series(Series::line("eumelanin", curve.clone()))
            .with_series(Series::dashed("messy", messy))
            .with_series(Series::scatter("points", curve[..5].to_vec()));
        let empty = LineChart::new("no data", "x", "y")
            .with_series(Series::line("nothing", vec![(f64::NAN, 1.0)]));
        let flat = LineChart::new("flat", "x", "y")
            .log_x()
            .with_series(Series::line("const", vec![(1.0, 2.0), (10.0, 2.0)]));
        let heat = HeatMap {
            title: "map".into(),
            x_label: "σa (mm⁻¹)".into(),
            y_label: "σs' (mm⁻¹)".into(),
            value_label: "R".into(),
            x_range: (0.01, 100.0),
            y_range: (0.0, 1.0),
            log_x: true,
            nx: 4,
            ny: 3,
            values: vec![
                0.0,
                0.1,
                0.2,
                0.3,
                0.4,
                f64::NAN,
                0.6,
                0.7,
                0.8,
                0.9,
                1.0,
                1.1,
            ],
            overlay: vec![Series::scatter("pts", vec![(1.0, 0.5)])],
            ..HeatMap::default()
        };
        vec![
            Panel::Line(lines),
            Panel::Line(empty),
            Panel::Line(flat),
            Panel::Heat(heat),
        ]
    }

    #[test]
    fn png_round_trip_has_size_and_content() {
        let dir = temp_dir("png");
        let path = dir.join("chart.png");
        save_png(&path, &sample_panels(), 640, 900).unwrap();
        let left = skin_io::atomic::leftovers(&dir, &["chart.png"]);
        assert!(left.is_empty(), "left behind: {left:?}");
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (640, 900));
        let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        // Axes, text, curves and the heat map cover well over 2% of the image; a blank one has 0.
        assert!(
            non_white > 640 * 900 / 50,
            "only {non_white} non-white pixels"
        );
        // The first series is drawn in the first palette colour; the heat map uses viridis.
        assert!(img.pixels().any(|p| p.0 == palette_color(0)));
        let viridis_end = ViridisRGB.get_color(1.0f64);
        assert!(
            img.pixels()
                .any(|p| p.0 == [viridis_end.0, viridis_end.1, viridis_end.2])
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn text_is_rendered_with_the_bundled_font() {
        // A chart with only a title: any dark pixel in the caption band comes from the font.
        let c = LineChart::new("TITLE", "", "");
        let buf = render_rgb(&[Panel::Line(c)], 200, 100).unwrap();
        let dark = buf.chunks(3).take(200 * 25).filter(|p| p[0] < 128).count();
        assert!(dark > 10, "caption not drawn ({dark} dark pixels)");
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let panels = sample_panels();
        assert!(matches!(
            render_rgb(&panels, 10, 600),
            Err(PlotError::Size { width: 10, .. })
        ));
        assert!(matches!(
            render_rgb(&[], 300, 300),
            Err(PlotError::NoPanels)
        ));
        let bad = HeatMap {
            nx: 2,
            ny: 2,
            values: vec![1.0; 3],
            ..HeatMap::default()
        };
        assert!(matches!(
            render_rgb(&[Panel::Heat(bad)], 300, 300),
            Err(PlotError::HeatMapShape { len: 3, .. })
        ));
    }

    #[test]
    fn ranges_are_padded_and_filtered() {
        assert_eq!(fit_range([].into_iter(), false), (0.0, 1.0));
        assert_eq!(fit_range([].into_iter(), true), (1.0, 10.0));
        let (a, b) = fit_range([2.0, 2.0].into_iter(), false);
        assert!(a < 2.0 && b > 2.0);
        let (a, b) = fit_range([-5.0, 0.1, 10.0, f64::NAN].into_iter(), true);
        assert_eq!((a, b), (0.1, 10.0));
        assert_eq!(fit_range([22.0, 142.0].into_iter(), true), (10.0, 1000.0));
        assert_eq!(fit_range([5.0].into_iter(), true), (1.0, 10.0));
        assert_eq!(sanitize_range((3.0, 1.0), false), (1.0, 3.0));
        let (a, _) = sanitize_range((0.0, 1.0), true);
        assert!(a > 0.0);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.0), "0");
        assert_eq!(tick_label(250.0), "250");
        assert_eq!(tick_label(0.5), "0.5");
        assert_eq!(tick_label(1e-5), "1e-5");
        assert_eq!(tick_label(1e6), "1e6");
    }
}
