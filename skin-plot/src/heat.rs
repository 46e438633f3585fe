//! Drawing of [`HeatMap`] panels: coloured cells (viridis), overlay series and a colour bar.

use super::line::{Axis, build_chart, draw_axes};
use super::{HeatMap, PlotError, SeriesStyle, draw_err, rgb, sanitize_range, tick_label, usable};
use plotters::coord::Shift;
use plotters::prelude::*;

pub(super) fn draw_heat_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    h: &HeatMap,
) -> Result<(), PlotError> {
    let (w, _) = area.dim_in_pixel();
    let bar_w = 110.min(w / 3);
    let (main, bar) = area.split_horizontally(w - bar_w);
    let (vmin, vmax) = h.value_range.map_or_else(
        || {
            // The colour scale spans the finite values exactly (no padding).
            let finite = h.values.iter().copied().filter(|v| v.is_finite());
            let lo = finite.clone().fold(f64::INFINITY, f64::min);
            let hi = finite.fold(f64::NEG_INFINITY, f64::max);
            sanitize_range((lo, hi), false)
        },
        |r| sanitize_range(r, false),
    );
    let xr = sanitize_range(h.x_range, h.log_x);
    let yr = sanitize_range(h.y_range, h.log_y);
    match (h.log_x, h.log_y) {
        (false, false) => draw_cells_in(&main, h, xr.0..xr.1, yr.0..yr.1, (vmin, vmax))?,
        (true, false) => {
            draw_cells_in(&main, h, (xr.0..xr.1).log_scale(), yr.0..yr.1, (vmin, vmax))?;
        }
        (false, true) => {
            draw_cells_in(&main, h, xr.0..xr.1, (yr.0..yr.1).log_scale(), (vmin, vmax))?;
        }
        (true, true) => draw_cells_in(
            &main,
            h,
            (xr.0..xr.1).log_scale(),
            (yr.0..yr.1).log_scale(),
            (vmin, vmax),
        )?,
    }
    draw_color_bar(&bar, &h.value_label, vmin, vmax)
}

/// Edge `k` of `n` equal cells over `r`, equal in log space on a log axis.
fn cell_edge(r: (f64, f64), n: usize, k: usize, log: bool) -> f64 {
    let t = k as f64 / n as f64;
    if log {
        (r.0.ln() + t * (r.1.ln() - r.0.ln())).exp()
    } else {
        r.0 + t * (r.1 - r.0)
    }
}

fn draw_cells_in<DB: DrawingBackend, X: Axis, Y: Axis>(
    area: &DrawingArea<DB, Shift>,
    h: &HeatMap,
    x: X,
    y: Y,
    (vmin, vmax): (f64, f64),
) -> Result<(), PlotError> {
    let xr = sanitize_range(h.x_range, h.log_x);
    let yr = sanitize_range(h.y_range, h.log_y);
    let mut chart = build_chart(area, &h.title, x, y)?;
    let cells = (0..h.ny).flat_map(|j| (0..h.nx).map(move |i| (i, j)));
    chart
        .draw_series(cells.map(|(i, j)| {
            let v = h.values[j * h.nx + i];
            let color = if v.is_finite() {
                ViridisRGB.get_color_normalized(v.clamp(vmin, vmax), vmin, vmax)
            } else {
                RGBColor(190, 190, 190)
            };
            let p0 = (
                cell_edge(xr, h.nx, i, h.log_x),
                cell_edge(yr, h.ny, j, h.log_y),
            );
            let p1 = (
                cell_edge(xr, h.nx, i + 1, h.log_x),
                cell_edge(yr, h.ny, j + 1, h.log_y),
            );
            Rectangle::new([p0, p1], color.filled())
        }))
        .map_err(draw_err)?;
    draw_axes(&mut chart, &h.x_label, &h.y_label, false)?;
    for s in &h.overlay {
        let color = rgb(s.color.unwrap_or([255, 255, 255]));
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| usable(*p, h.log_x, h.log_y))
            .collect();
        match s.style {
            SeriesStyle::Points => chart
                .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                .map_err(draw_err)?,
            SeriesStyle::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(2)))
                .map_err(draw_err)?,
            SeriesStyle::Line | SeriesStyle::LinePoints => chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(draw_err)?,
        };
    }
    Ok(())
}

fn draw_color_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    label: &str,
    vmin: f64,
    vmax: f64,
) -> Result<(), PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(55)
        .margin_right(10)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, vmin..vmax)
        .map_err(draw_err)?;
    const STEPS: usize = 128;
    chart
        .draw_series((0..STEPS).map(|k| {
            let a = vmin + (vmax - vmin) * k as f64 / STEPS as f64;
            let b = vmin + (vmax - vmin) * (k + 1) as f64 / STEPS as f64;
            let color = ViridisRGB.get_color_normalized(0.5 * (a + b), vmin, vmax);
            Rectangle::new([(0.0, a), (1.0, b)], color.filled())
        }))
        .map_err(draw_err)?;
    let fmt = |v: &f64| tick_label(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_formatter(&fmt)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(draw_err)?;
    Ok(())
}
