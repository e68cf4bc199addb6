//! The figures cdbo draws (track maps, learning curves, trade-off scatters, policies, speed
//! along the lap), with
//! plotters and a bundled DejaVu Sans font (no system font library needed). The file
//! extension chooses PNG or SVG.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::commands::CliResult;
use cdbo::limit::Limit;
use cdbo::sim::LapResult;
use cdbo::track::Track;

const SIZE: (u32, u32) = (1000, 800);

/// Something drawn on a drawing area of any backend.
pub trait Figure {
    /// Pixel size of the figure.
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    /// Draws the figure.
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> CliResult
    where
        DB::ErrorType: 'static;
}

/// The track map with both edges, its centre line coloured by curvature, or by speed.
pub struct TrackMap<'a> {
    /// The track.
    pub track: &'a Track,
    /// (distance, speed) along a lap to colour by, or `None` for the curvature.
    pub speeds: Option<&'a [(f64, f64)]>,
    /// A racing line's points to draw beside the centre line, with its name.
    pub line: Option<(&'a str, &'a [[f64; 2]])>,
}

impl Figure for TrackMap<'_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> CliResult
    where
        DB::ErrorType: 'static,
    {
        track_map(root, self)
    }
}

/// One line of a chart: its legend label, its colour and its points.
pub type Series = (String, RGBColor, Vec<(f64, f64)>);

/// A line chart: named series of (x, y) points.
pub struct LineChart {
    /// Title.
    pub title: String,
    /// Axis label.
    pub x_label: String,
    /// Axis label.
    pub y_label: String,
    /// (label, colour, points).
    pub series: Vec<Series>,
}

impl LineChart {
    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in self.series.iter().flat_map(|s| s.2.iter()) {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        if x0 > x1 {
            return ((0.0, 1.0), (0.0, 1.0));
        }
        let pad = 0.05 * (y1 - y0).max(1e-9);
        ((x0, x1.max(x0 + 1e-9)), (y0 - pad, y1 + pad))
    }
}

/// A chart over f64 × f64 on a drawing area.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A chart of the whole figure over x × y, the title on top and room for the axes' labels.
fn titled<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
) -> Result<Chart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    ChartBuilder::on(root)
        .caption(title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)
}

impl Figure for LineChart {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> CliResult
    where
        DB::ErrorType: 'static,
    {
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = titled(root, &self.title, x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .draw()?;
        for (label, colour, points) in &self.series {
            let c = *colour;
            chart
                .draw_series(LineSeries::new(points.iter().copied(), c.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .draw()?;
        Ok(())
    }
}

/// A curve with a shaded band: label, colour and (x, mean, half-width) points.
pub type Band = (String, RGBColor, Vec<(f64, f64, f64)>);

/// Side-by-side panels of curves with shaded bands (mean ± standard error), sharing the
/// legend's colours: the paper's Fig. 4 and 5.
pub struct Panels {
    /// Title of each panel.
    pub titles: Vec<String>,
    /// Axis label.
    pub x_label: String,
    /// Axis label.
    pub y_label: String,
    /// The bands of each panel.
    pub panels: Vec<Vec<Band>>,
}

impl Figure for Panels {
    fn size(&self) -> (u32, u32) {
        (520 * self.panels.len().max(1) as u32, 560)
    }

    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> CliResult
    where
        DB::ErrorType: 'static,
    {
        let areas = root.split_evenly((1, self.panels.len().max(1)));
        for ((area, bands), title) in areas.iter().zip(&self.panels).zip(&self.titles) {
            let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for &(x, m, h) in bands.iter().flat_map(|b| b.2.iter()) {
                (x0, x1) = (x0.min(x), x1.max(x));
                (y0, y1) = (y0.min(m - h), y1.max(m + h));
            }
            if x0 > x1 {
                continue;
            }
            let pad = 0.05 * (y1 - y0).max(1e-9);
            let mut chart = ChartBuilder::on(area)
                .caption(title, ("sans-serif", 22))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1.max(x0 + 1e-9), (y0 - pad)..(y1 + pad))?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .draw()?;
            for (label, colour, points) in bands {
                let c = *colour;
                let outline: Vec<(f64, f64)> = points
                    .iter()
                    .map(|p| (p.0, p.1 + p.2))
                    .chain(points.iter().rev().map(|p| (p.0, p.1 - p.2)))
                    .collect();
                chart.draw_series(std::iter::once(Polygon::new(outline, c.mix(0.2).filled())))?;
                chart
                    .draw_series(LineSeries::new(
                        points.iter().map(|p| (p.0, p.1)),
                        c.stroke_width(2),
                    ))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], c.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .border_style(BLACK)
                .background_style(WHITE.mix(0.8))
                .draw()?;
        }
        Ok(())
    }
}

/// One group of a [`Scatter`]: its legend label, its colour, each member's (x, y), and their
/// mean with its standard errors ((x, y), (x_se, y_se)).
pub struct Cloud {
    /// Legend label.
    pub label: String,
    /// Colour.
    pub colour: RGBColor,
    /// (x, y) of each member (each run).
    pub points: Vec<(f64, f64)>,
    /// Mean (x, y).
    pub mean: (f64, f64),
    /// Standard errors of the mean (x, y).
    pub se: (f64, f64),
}

/// A scatter of groups: each member a faint dot, each group's mean a filled dot with error
/// bars of ± one standard error on both axes; and vertical reference lines (a failure budget).
/// The legend goes in the corner of the plot with the fewest dots, so that it hides none it
/// can avoid.
pub struct Scatter {
    /// Title.
    pub title: String,
    /// Axis label.
    pub x_label: String,
    /// Axis label.
    pub y_label: String,
    /// The groups.
    pub clouds: Vec<Cloud>,
    /// Vertical lines: (legend label, x).
    pub marks: Vec<(String, f64)>,
}

impl Scatter {
    /// x from 0 (a count) to past the last dot, bar or mark; y around the dots and bars.
    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let (mut x1, mut y0, mut y1) = (0.0f64, f64::MAX, f64::MIN);
        for c in &self.clouds {
            let (m, e) = (c.mean, c.se);
            for (x, y) in c
                .points
                .iter()
                .copied()
                .chain([(m.0 + e.0, m.1 + e.1), (m.0, m.1 - e.1)])
            {
                (x1, y0, y1) = (x1.max(x), y0.min(y), y1.max(y));
            }
        }
        for (_, x) in &self.marks {
            x1 = x1.max(*x);
        }
        if y0 > y1 {
            return ((0.0, 1.0), (0.0, 1.0));
        }
        let pad = 0.08 * (y1 - y0).max(1e-9);
        ((0.0, 1.08 * x1.max(1.0)), (y0 - pad, y1 + pad))
    }

    /// The corner of the plot holding the fewest dots (means and members).
    fn emptiest_corner(&self, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> SeriesLabelPosition {
        let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let dots: Vec<(f64, f64)> = self
            .clouds
            .iter()
            .flat_map(|c| c.points.iter().copied().chain([c.mean]))
            .collect();
        let count = |right: bool, top: bool| {
            dots.iter()
                .filter(|(x, y)| (*x >= xm) == right && (*y >= ym) == top)
                .count()
        };
        [
            (SeriesLabelPosition::UpperRight, count(true, true)),
            (SeriesLabelPosition::LowerRight, count(true, false)),
            (SeriesLabelPosition::UpperLeft, count(false, true)),
            (SeriesLabelPosition::LowerLeft, count(false, false)),
        ]
        .into_iter()
        .min_by_key(|c| c.1)
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
    }
}

impl Figure for Scatter {
    fn size(&self) -> (u32, u32) {
        (900, 640)
    }

    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> CliResult
    where
        DB::ErrorType: 'static,
    {
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = titled(root, &self.title, x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()?;
        let grey = RGBColor(90, 90, 90);
        for (label, x) in &self.marks {
            chart
                .draw_series(DashedLineSeries::new(
                    [(*x, y0), (*x, y1)],
                    8,
                    5,
                    grey.stroke_width(1),
                ))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], grey.stroke_width(1))
                });
        }
        for cloud in &self.clouds {
            let c = cloud.colour;
            chart.draw_series(
                cloud
                    .points
                    .iter()
                    .map(|&p| Circle::new(p, 4, c.mix(0.35).filled())),
            )?;
            let ((mx, my), (ex, ey)) = (cloud.mean, cloud.se);
            chart.draw_series(std::iter::once(ErrorBar::new_horizontal(
                my,
                mx - ex,
                mx,
                mx + ex,
                c.stroke_width(2),
                10,
            )))?;
            chart.draw_series(std::iter::once(ErrorBar::new_vertical(
                mx,
                my - ey,
                my,
                my + ey,
                c.stroke_width(2),
                10,
            )))?;
            chart
                .draw_series(std::iter::once(Circle::new((mx, my), 7, c.filled())))?
                .label(&cloud.label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 6, c.filled()));
        }
        chart
            .configure_series_labels()
            .position(self.emptiest_corner((x0, x1), (y0, y1)))
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()?;
        Ok(())
    }
}

/// Speed along the lap against the limit profile.
pub fn lap_speed(path: &Path, track: &Track, lap: &LapResult, limit: &Limit) -> CliResult {
    draw(path, &speed_chart(track, &[("lap", BLUE, lap)], limit))
}

/// Speeds of several laps along the track with the limit's profile (paper Fig. 3b).
pub fn speed_chart(
    track: &Track,
    laps: &[(&str, RGBColor, &LapResult)],
    limit: &Limit,
) -> LineChart {
    let ds = track.ds;
    let mut series = vec![(
        "limit (QSS)".to_owned(),
        RED,
        limit
            .speed
            .iter()
            .enumerate()
            .map(|(i, v)| (i as f64 * ds, *v))
            .collect(),
    )];
    for (label, colour, lap) in laps {
        series.push((
            (*label).to_owned(),
            *colour,
            lap.trace.iter().map(|p| (p.distance_m, p.speed)).collect(),
        ));
    }
    LineChart {
        title: format!("{}: speed along the lap", track.name),
        x_label: "distance (m)".into(),
        y_label: "speed (m/s)".into(),
        series,
    }
}

/// The track map coloured by a lap's speed.
pub fn speed_map(
    path: &Path,
    track: &Track,
    lap: &LapResult,
    line: Option<(&str, &[[f64; 2]])>,
) -> CliResult {
    let speeds: Vec<(f64, f64)> = lap.trace.iter().map(|p| (p.distance_m, p.speed)).collect();
    draw(
        path,
        &TrackMap {
            track,
            speeds: Some(&speeds),
            line,
        },
    )
}

fn track_map<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, map: &TrackMap) -> CliResult
where
    DB::ErrorType: 'static,
{
    let (t, speeds) = (map.track, map.speeds);
    let edge = |side: f64| -> Vec<(f64, f64)> {
        t.samples
            .iter()
            .map(|c| {
                (
                    c.x - side * 0.5 * c.width * c.heading.sin(),
                    c.y + side * 0.5 * c.width * c.heading.cos(),
                )
            })
            .collect()
    };
    let (left, right) = (edge(1.0), edge(-1.0));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in left.iter().chain(&right) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    // Equal scales on both axes.
    let (w, h) = (x1 - x0, y1 - y0);
    let aspect = (SIZE.0 - 100) as f64 / (SIZE.1 - 100) as f64;
    let (w, h) = if w / h > aspect {
        (w, w / aspect)
    } else {
        (h * aspect, h)
    };
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let title = match speeds {
        Some(_) => format!("{} — coloured by speed", t.name),
        None => format!("{} ({:.0} m) — coloured by curvature", t.name, t.length),
    };
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(cx - 0.55 * w..cx + 0.55 * w, cy - 0.55 * h..cy + 0.55 * h)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .draw()?;
    let n = t.len();
    let value = |i: usize| -> f64 {
        match speeds {
            Some(sp) => speed_at(sp, t.samples[i].s),
            None => t.samples[i].curvature.abs(),
        }
    };
    let vmax = (0..n).map(value).fold(1e-9, f64::max);
    let centre_colour = |i: usize| {
        plotters::style::colors::colormaps::ViridisRGB::get_color((value(i) / vmax).clamp(0.0, 1.0))
    };
    chart.draw_series((0..n).map(|i| {
        let (a, b) = (&t.samples[i], &t.samples[(i + 1) % n]);
        PathElement::new([(a.x, a.y), (b.x, b.y)], centre_colour(i).stroke_width(4))
    }))?;
    for e in [&left, &right] {
        chart.draw_series(std::iter::once(PathElement::new(
            e.iter().chain(e.first()).copied().collect::<Vec<_>>(),
            BLACK.stroke_width(1),
        )))?;
    }
    if let Some((_, points)) = map.line {
        chart.draw_series(std::iter::once(PathElement::new(
            points
                .iter()
                .chain(points.first())
                .map(|p| (p[0], p[1]))
                .collect::<Vec<_>>(),
            MAGENTA.stroke_width(1),
        )))?;
    }
    let s0 = &t.samples[0];
    chart.draw_series(std::iter::once(Circle::new((s0.x, s0.y), 6, RED.filled())))?;
    let mut label = match speeds {
        Some(_) => format!("speed 0 .. {vmax:.1} m/s (dark → bright); red dot: start"),
        None => format!("|curvature| 0 .. {vmax:.3} 1/m (dark → bright); red dot: start"),
    };
    if let Some((name, _)) = map.line {
        label += &format!("; magenta: the {name}");
    }
    root.draw(&Text::new(
        label,
        (80, (SIZE.1 - 30) as i32),
        ("sans-serif", 16),
    ))?;
    Ok(())
}

/// (distance, speed) rows of a `cdbo lap --trace` file ([`cdbo::sim::trace`]).
pub fn read_trace_speeds(path: &Path) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    let trace = cdbo::sim::trace::read(path)?;
    if trace.is_empty() {
        return Err(format!("{}: no rows", path.display()).into());
    }
    Ok(trace.iter().map(|p| (p.distance_m, p.speed)).collect())
}

fn speed_at(rows: &[(f64, f64)], s: f64) -> f64 {
    let i = rows.partition_point(|r| r.0 <= s);
    rows[i.saturating_sub(1).min(rows.len() - 1)].1
}

/// Renders `f` into a PNG or SVG file chosen by the extension; every error names the file.
pub fn draw(path: &Path, figure: &impl Figure) -> CliResult {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        // The bundled font is valid, so registration cannot fail.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(folder) = folder.filter(|f| !f.is_dir()) {
        return Err(format!(
            "{}: cannot write the plot: the folder {} does not exist",
            path.display(),
            folder.display()
        )
        .into());
    }
    let drawn: CliResult = match path.extension().and_then(|e| e.to_str()) {
        Some("svg") => (|| {
            let root = SVGBackend::new(path, figure.size()).into_drawing_area();
            root.fill(&WHITE)?;
            figure.render(&root)?;
            root.present()?;
            Ok(())
        })(),
        Some("png") => (|| {
            let root = BitMapBackend::new(path, figure.size()).into_drawing_area();
            root.fill(&WHITE)?;
            figure.render(&root)?;
            root.present()?;
            Ok(())
        })(),
        _ => Err("the plot file must end in .png or .svg".into()),
    };
    drawn.map_err(|e| format!("{}: {e}", path.display()).into())
}
