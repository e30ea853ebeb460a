//! Error-versus-time plots: log–log, one curve per configuration.

use super::converge::Row;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    rows: &[Row],
    names: &[String],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let pos = |v: f64| v > 0.0 && v.is_finite();
    let ts: Vec<f64> = rows.iter().map(|r| r.seconds).filter(|v| pos(*v)).collect();
    let es: Vec<f64> = rows
        .iter()
        .flat_map(|r| [Some(r.relmse), r.estimate])
        .flatten()
        .filter(|v| pos(*v))
        .collect();
    if ts.is_empty() || es.is_empty() {
        return Err("nothing to plot: no rung has a positive time and error".into());
    }
    let (t0, t1) = ts
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &v| (a.0.min(v), a.1.max(v)));
    let (e0, e1) = es
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &v| (a.0.min(v), a.1.max(v)));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (t0 / 1.5..t1 * 1.5).log_scale(),
            (e0 / 2.0..e1 * 2.0).log_scale(),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("seconds")
        .y_desc("relMSE")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| err(&e))?;
    for (i, name) in names.iter().enumerate() {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| &r.config == name && pos(r.seconds) && pos(r.relmse))
            .map(|r| (r.seconds, r.relmse))
            .collect();
        let c = COLORS[i % COLORS.len()];
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
            .map_err(|e| err(&e))?;
        // The render's own estimate beside the true error: hollow markers, thin line.
        let est: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| &r.config == name && pos(r.seconds))
            .filter_map(|r| r.estimate.filter(|e| pos(*e)).map(|e| (r.seconds, e)))
            .collect();
        if !est.is_empty() {
            chart
                .draw_series(LineSeries::new(est.clone(), c.stroke_width(1)))
                .map_err(|e| err(&e))?
                .label(format!("{name} (estimated)"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(1))
                });
            chart
                .draw_series(est.iter().map(|p| Circle::new(*p, 4, c.stroke_width(1))))
                .map_err(|e| err(&e))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Registers the plots' typeface once: DejaVu Sans, compiled in (`assets/fonts/`), so text
/// is drawn in pure Rust with no system font libraries to find or install.
fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        let bytes = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| "the plots' typeface cannot be read".to_string())
    })
    .clone()
}

/// Writes the plot as PNG and SVG.
pub fn plot(
    title: &str,
    rows: &[Row],
    names: &[String],
    png: &Path,
    svg: &Path,
) -> Result<(), String> {
    register_font()?;
    draw(
        BitMapBackend::new(png, (800, 500)).into_drawing_area(),
        title,
        rows,
        names,
    )
    .map_err(|e| format!("cannot draw '{}': {e}", png.display()))?;
    draw(
        SVGBackend::new(svg, (800, 500)).into_drawing_area(),
        title,
        rows,
        names,
    )
    .map_err(|e| format!("cannot draw '{}': {e}", svg.display()))?;
    Ok(())
}
