//! Report charts as PNG: scatter / line series on linear or log axes, with readable tick labels
//! on log axes (1-2-5 steps, or every integer mantissa when the range spans less than a decade),
//! one colour AND one marker shape per series, the legend beside the plot area (never over the
//! data), and wrapped footnotes below it, with margins so that nothing is clipped.
//!
//! ```no_run
//! use host::plot::{Axis, Plot, Series};
//! let plot = Plot {
//!     title: "error vs time".into(),
//!     x: Axis::log("time (ms)"),
//!     y: Axis::log("max abs error"),
//!     series: vec![Series::line("cpu 32x32", vec![(1.0, 1e-2), (4.0, 5e-3)])],
//!     footnotes: vec!["CPU: native backend".into()],
//!     ..Plot::default()
//! };
//! plot.save_png(std::path::Path::new("out/example.png")).unwrap();
//! ```

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// How an axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// log10; values <= 0 or non-finite are left out of the chart.
    Log,
}

/// An axis: its title and scale.
#[derive(Clone, Debug)]
pub struct Axis {
    pub label: String,
    pub scale: Scale,
}

impl Axis {
    pub fn linear(label: &str) -> Axis {
        Axis { label: label.into(), scale: Scale::Linear }
    }
    pub fn log(label: &str) -> Axis {
        Axis { label: label.into(), scale: Scale::Log }
    }
    /// The chart coordinate of `v` (log10 for log axes); `None` where it cannot be drawn.
    fn to_chart(&self, v: f64) -> Option<f64> {
        match self.scale {
            Scale::Linear if v.is_finite() => Some(v),
            Scale::Log if v.is_finite() && v > 0.0 => Some(v.log10()),
            _ => None,
        }
    }
    #[allow(clippy::wrong_self_convention)] // the inverse of `to_chart`, on the axis's scale
    fn from_chart(&self, c: f64) -> f64 {
        match self.scale {
            Scale::Linear => c,
            Scale::Log => 10f64.powf(c),
        }
    }
}

/// One data series: points in data units, drawn as markers, joined by a line when `joined`,
/// each point optionally annotated (`point_labels[i]` beside point `i`; empty = none).
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub joined: bool,
    pub point_labels: Vec<String>,
}

impl Series {
    /// Markers joined by a line.
    pub fn line(label: &str, points: Vec<(f64, f64)>) -> Series {
        Series { label: label.into(), points, joined: true, point_labels: Vec::new() }
    }
    /// Markers only.
    pub fn scatter(label: &str, points: Vec<(f64, f64)>) -> Series {
        Series { label: label.into(), points, joined: false, point_labels: Vec::new() }
    }
}

/// A chart. Series `i` is drawn in colour `PALETTE[i % 12]` with marker `MARKERS[i % 6]`, so
/// up to 12 series differ in colour and any two series differ in colour or marker.
#[derive(Clone, Debug)]
pub struct Plot {
    pub title: String,
    pub x: Axis,
    pub y: Axis,
    pub series: Vec<Series>,
    /// Lines below the chart (wrapped to the image width).
    pub footnotes: Vec<String>,
    /// Image size in pixels.
    pub size: (u32, u32),
}

impl Default for Plot {
    fn default() -> Self {
        Plot { title: String::new(), x: Axis::linear(""), y: Axis::linear(""), series: Vec::new(), footnotes: Vec::new(), size: (1400, 900) }
    }
}

/// Series colours (distinguishable, dark enough on white).
#[rustfmt::skip]
pub const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(148, 103, 189),
    RGBColor(255, 127, 14), RGBColor(23, 190, 207), RGBColor(140, 86, 75), RGBColor(227, 119, 194),
    RGBColor(127, 127, 127), RGBColor(188, 189, 34), RGBColor(0, 0, 0), RGBColor(0, 90, 50),
];

/// Marker shapes, in series order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
    Ring,
}

pub const MARKERS: [Marker; 6] = [Marker::Circle, Marker::Square, Marker::TriangleUp, Marker::Diamond, Marker::TriangleDown, Marker::Ring];

const FONT_SIZE: u32 = 18;
const MARKER_RADIUS: i32 = 7;
/// Font size of point labels.
const LABEL_SIZE: u32 = 15;

fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing the chart: {e}")
}

/// Register the bundled font once (plotters' bitmap backend has no system fonts here).
fn register_font() {
    static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Draw the marker of series `k` centred at backend pixel `(x, y)` of `area`.
fn draw_marker<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, k: usize, color: RGBColor, (x, y): (i32, i32)) -> Result<()> {
    let r = MARKER_RADIUS;
    let fill = color.filled();
    let poly = |pts: &[(i32, i32)]| Polygon::new(pts.iter().map(|&(dx, dy)| (x + dx, y + dy)).collect::<Vec<_>>(), fill);
    match MARKERS[k % MARKERS.len()] {
        Marker::Circle => area.draw(&Circle::new((x, y), r, fill)),
        Marker::Ring => area.draw(&Circle::new((x, y), r, color.stroke_width(3))),
        Marker::Square => area.draw(&Rectangle::new([(x - r + 1, y - r + 1), (x + r - 1, y + r - 1)], fill)),
        Marker::TriangleUp => area.draw(&poly(&[(0, -r - 1), (r, r - 1), (-r, r - 1)])),
        Marker::TriangleDown => area.draw(&poly(&[(0, r + 1), (r, -r + 1), (-r, -r + 1)])),
        Marker::Diamond => area.draw(&poly(&[(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)])),
    }
    .map_err(err)
}

/// A linear chart axis over `lo..hi` whose labelled positions are exactly `ticks`.
#[derive(Clone)]
struct Ticked {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl plotters::coord::ranged1d::Ranged for Ticked {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (f64::from(limit.1 - limit.0) * t).round() as i32
    }
    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, _hint: H) -> Vec<f64> {
        self.ticks.clone()
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Tick positions (in chart coordinates) for the range `lo..hi` of `axis`, at least 3 of them.
fn ticks(axis: &Axis, lo: f64, hi: f64) -> Vec<f64> {
    match axis.scale {
        Scale::Log => {
            let pick = |mantissas: &[f64]| -> Vec<f64> {
                let mut v = Vec::new();
                for e in (lo.floor() as i32 - 1)..=(hi.ceil() as i32) {
                    for m in mantissas {
                        let c = (m * 10f64.powi(e)).log10();
                        if c >= lo && c <= hi {
                            v.push(c);
                        }
                    }
                }
                v
            };
            let decades = pick(&[1.0]);
            if decades.len() >= 3 {
                // Many decades: every decade, or every other one when crowded.
                let step = decades.len().div_ceil(10);
                return decades.into_iter().step_by(step).collect();
            }
            let v = pick(&[1.0, 2.0, 5.0]);
            if v.len() >= 3 {
                v
            } else {
                pick(&[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            }
        }
        Scale::Linear => {
            let raw = (hi - lo) / 6.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
            let mut v = Vec::new();
            let mut t = (lo / step).ceil() * step;
            while t <= hi + step * 1e-9 {
                v.push(t);
                t += step;
            }
            v
        }
    }
}

/// A short tick label: 0.002, 0.5, 30, 2000, 2e-5, 3e+6.
pub fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.1e}");
        return s.replace(".0e", "e");
    }
    let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Chart-coordinate range covering `values` with a margin (a decade's tenth on log axes).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(0.1);
    (lo - pad, hi + pad)
}

/// Split `text` into lines of at most `width` characters at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.len() + 1 + word.len() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

impl Plot {
    /// Draw the chart into an RGB buffer (`size.0 * size.1 * 3` bytes).
    pub fn render(&self) -> Result<Vec<u8>> {
        register_font();
        let (w, h) = self.size;
        let mut buf = vec![255u8; (w * h * 3) as usize];
        let pts: Vec<Vec<(f64, f64, usize)>> = self
            .series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &(x, y))| Some((self.x.to_chart(x)?, self.y.to_chart(y)?, i)))
                    .collect()
            })
            .collect();
        let (x0, x1) = range(pts.iter().flatten().map(|p| p.0));
        let (y0, y1) = range(pts.iter().flatten().map(|p| p.1));
        let (xt, yt) = (ticks(&self.x, x0, x1), ticks(&self.y, y0, y1));
        let char_w = FONT_SIZE as usize * 55 / 100;
        let foot_lines: Vec<String> = self.footnotes.iter().flat_map(|f| wrap(f, (w as usize - 60) / char_w)).collect();
        let foot_h = if foot_lines.is_empty() { 0 } else { foot_lines.len() as u32 * (FONT_SIZE + 6) + 20 };
        let longest = self.series.iter().map(|s| s.label.chars().count()).max().unwrap_or(0);
        let legend_w = if self.series.is_empty() { 0 } else { (longest * char_w) as u32 + 80 };
        let y_label_w = yt.iter().map(|&t| tick_label(self.y.from_chart(t)).len()).max().unwrap_or(1) as u32 * char_w as u32 + 50;
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let (main, foot) = root.split_vertically(h - foot_h);
            let (area, legend) = main.split_horizontally(w - legend_w);
            let mut chart = ChartBuilder::on(&area)
                .caption(&self.title, ("sans-serif", FONT_SIZE + 8))
                .margin(25)
                .x_label_area_size(FONT_SIZE * 4)
                .y_label_area_size(y_label_w)
                .build_cartesian_2d(Ticked { lo: x0, hi: x1, ticks: xt }, Ticked { lo: y0, hi: y1, ticks: yt })
                .map_err(err)?;
            let (fx, fy) = (|c: &f64| tick_label(self.x.from_chart(*c)), |c: &f64| tick_label(self.y.from_chart(*c)));
            chart
                .configure_mesh()
                .x_desc(&self.x.label)
                .y_desc(&self.y.label)
                .x_label_formatter(&fx)
                .y_label_formatter(&fy)
                .label_style(("sans-serif", FONT_SIZE))
                .axis_desc_style(("sans-serif", FONT_SIZE + 2))
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(err)?;
            let text = |color: RGBColor| ("sans-serif", FONT_SIZE).into_font().color(&color);
            // Point labels: the first free spot (right, left, above, below the marker) inside
            // the plot area that overlaps no earlier label; the first candidate if none is free.
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let m = MARKER_RADIUS;
            let mut placed: Vec<[i32; 4]> = pts
                .iter()
                .flatten()
                .map(|q| chart.backend_coord(&(q.0, q.1)))
                .map(|(x, y)| [x - m, y - m, x + m, y + m])
                .collect();
            for (k, (s, p)) in self.series.iter().zip(&pts).enumerate() {
                let color = PALETTE[k % PALETTE.len()];
                if s.joined && p.len() > 1 {
                    chart.draw_series(std::iter::once(PathElement::new(p.iter().map(|q| (q.0, q.1)).collect::<Vec<_>>(), color.stroke_width(2)))).map_err(err)?;
                }
                for q in p {
                    draw_marker(&root, k, color, chart.backend_coord(&(q.0, q.1)))?;
                }
                for q in p {
                    let Some(l) = s.point_labels.get(q.2).filter(|l| !l.is_empty()) else { continue };
                    let (px, py) = chart.backend_coord(&(q.0, q.1));
                    let (w, h) = (l.chars().count() as i32 * LABEL_SIZE as i32 * 6 / 10, LABEL_SIZE as i32);
                    let r = MARKER_RADIUS + 3;
                    let spots = [(r, -h / 2), (-r - w, -h / 2), (-w / 2, -r - h), (-w / 2, r), (r, -r - h), (r, r), (-r - w, -r - h), (-r - w, r)];
                    let rects = spots.map(|(dx, dy)| [px + dx, py + dy, px + dx + w, py + dy + h]);
                    let free = |b: &[i32; 4]| {
                        xr.contains(&b[0]) && xr.contains(&b[2]) && yr.contains(&b[1]) && yr.contains(&b[3])
                            && !placed.iter().any(|a| a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3])
                    };
                    let b = rects.iter().find(|b| free(b)).copied().unwrap_or(rects[0]);
                    placed.push(b);
                    root.draw(&Text::new(l.clone(), (b[0], b[1]), ("sans-serif", LABEL_SIZE).into_font().color(&color))).map_err(err)?;
                }
            }
            for (k, s) in self.series.iter().enumerate() {
                let color = PALETTE[k % PALETTE.len()];
                let y = 60 + k as i32 * (FONT_SIZE as i32 + 12);
                if s.joined {
                    legend.draw(&PathElement::new(vec![(5, y), (45, y)], color.stroke_width(2))).map_err(err)?;
                }
                draw_marker(&legend, k, color, (25, y))?;
                legend.draw(&Text::new(s.label.clone(), (55, y - FONT_SIZE as i32 / 2), text(BLACK))).map_err(err)?;
            }
            for (i, l) in foot_lines.iter().enumerate() {
                foot.draw(&Text::new(l.clone(), (30, 5 + i as i32 * (FONT_SIZE as i32 + 6)), text(BLACK))).map_err(err)?;
            }
            root.present().map_err(err)?;
        }
        Ok(buf)
    }

    /// Draw the chart and write it as PNG (atomically: an existing file is replaced only by a
    /// complete new one).
    pub fn save_png(&self, path: &Path) -> Result<()> {
        let buf = self.render()?;
        let (w, h) = self.size;
        crate::io::write_atomic(path, |tmp| {
            image::save_buffer_with_format(tmp, &buf, w, h, image::ColorType::Rgb8, image::ImageFormat::Png).map_err(anyhow::Error::from)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_at_least_three_and_labelled_briefly() {
        let a = Axis::log("");
        // Less than a decade: 2e-3 .. 6e-3.
        let t = ticks(&a, (2e-3f64).log10(), (6e-3f64).log10());
        assert!(t.len() >= 3, "{t:?}");
        let labels: Vec<String> = t.iter().map(|&c| tick_label(a.from_chart(c))).collect();
        assert!(labels.iter().all(|l| l.len() <= 6), "{labels:?}");
        assert_eq!(tick_label(2e-5), "2e-5");
        assert_eq!(tick_label(0.5), "0.5");
        assert_eq!(tick_label(2000.0), "2000");
    }

    #[test]
    fn wraps_at_spaces() {
        assert_eq!(wrap("aa bb cc", 5), vec!["aa bb", "cc"]);
    }
}
