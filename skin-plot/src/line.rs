//! Drawing of [`LineChart`] panels (lines, dashes, scatter, legend) on linear or log axes.

use super::{
    LineChart, PlotError, SeriesStyle, draw_err, fit_range, palette_color, rgb, sanitize_range,
    tick_label, usable,
};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;

/// The chart type `build_chart` returns for axis specs `X`, `Y`.
pub(super) type Chart<'b, DB, X, Y> = ChartContext<
    'b,
    DB,
    Cartesian2d<<X as AsRangedCoord>::CoordDescType, <Y as AsRangedCoord>::CoordDescType>,
>;

/// An axis spec whose coordinates are f64 with tick labels: what every panel draws on.
pub(super) trait Axis:
    AsRangedCoord<Value = f64, CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>>
{
}

impl<T> Axis for T where
    T: AsRangedCoord<Value = f64, CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>>
{
}

pub(super) fn draw_line_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &LineChart,
) -> Result<(), PlotError> {
    let ok = |p: &&(f64, f64)| usable(**p, c.log_x, c.log_y);
    let fitted_x = fit_range(
        c.series
            .iter()
            .flat_map(|s| s.points.iter().filter(ok).map(|p| p.0)),
        c.log_x,
    );
    let fitted_y = fit_range(
        c.series
            .iter()
            .flat_map(|s| s.points.iter().filter(ok).map(|p| p.1)),
        c.log_y,
    );
    let xr = c.x_range.map_or(fitted_x, |r| sanitize_range(r, c.log_x));
    let yr = c.y_range.map_or(fitted_y, |r| sanitize_range(r, c.log_y));
    match (c.log_x, c.log_y) {
        (false, false) => draw_lines_in(area, c, xr.0..xr.1, yr.0..yr.1),
        (true, false) => draw_lines_in(area, c, (xr.0..xr.1).log_scale(), yr.0..yr.1),
        (false, true) => draw_lines_in(area, c, xr.0..xr.1, (yr.0..yr.1).log_scale()),
        (true, true) => draw_lines_in(area, c, (xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale()),
    }
}

pub(super) fn build_chart<'a, 'b, DB, X, Y>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: X,
    y: Y,
) -> Result<Chart<'b, DB, X, Y>, PlotError>
where
    'a: 'b,
    DB: DrawingBackend + 'a,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
{
    let (_, h) = area.dim_in_pixel();
    let title_px = (h as f64 * 0.06).clamp(14.0, 24.0);
    ChartBuilder::on(area)
        .caption(title, ("sans-serif", title_px))
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(draw_err)
}

/// Axes with tick labels and their descriptions, and the grid when `grid` (every panel's style).
pub(super) fn draw_axes<DB, XC, YC>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<XC, YC>>,
    x_label: &str,
    y_label: &str,
    grid: bool,
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    XC: Ranged<ValueType = f64> + ValueFormatter<f64>,
    YC: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let fmt = |v: &f64| tick_label(*v);
    let mut mesh = chart.configure_mesh();
    if !grid {
        mesh.disable_mesh();
    }
    mesh.x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(draw_err)
}

fn draw_lines_in<DB: DrawingBackend, X: Axis, Y: Axis>(
    area: &DrawingArea<DB, Shift>,
    c: &LineChart,
    x: X,
    y: Y,
) -> Result<(), PlotError> {
    let mut chart = build_chart(area, &c.title, x, y)?;
    draw_axes(&mut chart, &c.x_label, &c.y_label, true)?;

    let mut any_legend = false;
    for (i, s) in c.series.iter().enumerate() {
        let color = rgb(s.color.unwrap_or(palette_color(i)));
        let line = color.stroke_width(2);
        // Runs of consecutive usable points: a skipped point breaks the line there.
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &p in &s.points {
            if usable(p, c.log_x, c.log_y) {
                if let Some(run) = runs.last_mut() {
                    run.push(p);
                }
            } else if runs.last().is_some_and(|r| !r.is_empty()) {
                runs.push(Vec::new());
            }
        }
        for (k, run) in runs.into_iter().enumerate() {
            let anno = match s.style {
                SeriesStyle::Line => chart
                    .draw_series(LineSeries::new(run, line))
                    .map_err(draw_err)?,
                SeriesStyle::Dashed => chart
                    .draw_series(DashedLineSeries::new(run, 8, 5, line))
                    .map_err(draw_err)?,
                SeriesStyle::Points => chart
                    .draw_series(run.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .map_err(draw_err)?,
                SeriesStyle::LinePoints => chart
                    .draw_series(LineSeries::new(run, line).point_size(3))
                    .map_err(draw_err)?,
            };
            if k == 0 && !s.name.is_empty() {
                any_legend = true;
                let (ends, middle, dot) = match s.style {
                    SeriesStyle::Line => (1.0, 1.0, 0),
                    SeriesStyle::Dashed => (1.0, 0.0, 0),
                    SeriesStyle::Points => (0.0, 0.0, 4),
                    SeriesStyle::LinePoints => (1.0, 1.0, 3),
                };
                // One element type for every style: a 20-px line in three pieces plus a dot.
                anno.label(s.name.as_str()).legend(move |(lx, ly)| {
                    let seg = |a: i32, b: i32, alpha: f64| {
                        PathElement::new(vec![(a, 0), (b, 0)], color.mix(alpha).stroke_width(2))
                    };
                    EmptyElement::at((lx, ly))
                        + seg(0, 8, ends)
                        + seg(8, 12, middle)
                        + seg(12, 20, ends)
                        + Circle::new((10, 0), dot, color.filled())
                });
            }
        }
    }
    if any_legend {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(draw_err)?;
    }
    Ok(())
}
