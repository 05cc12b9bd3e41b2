//! SVG plots of quality reports: two histogram panels side by side under a title.
//!
//! - Tet meshes ([`write_quality_svg`]): all dihedral angles (10° bins) with the 5/10/20° and
//!   160/170/175° thresholds and the regular tet's 70.53° marked; all solid angles (0.05 sr bins)
//!   with the regular tet's 0.5513 sr marked.
//! - 2D triangle meshes ([`write_tri_quality_svg`]): all angles (10° bins) and the smallest angle
//!   of each triangle (5° bins), thresholds and the equilateral 60° marked.
//!
//! Counts are on a **log scale**. Quality is decided by the tails: a mesh of a million tets with
//! thirty slivers has a few bins holding 1–30 elements next to bins holding 10⁶; on a linear axis
//! those bars are under a pixel tall and the plot looks perfect. On a log axis a single element
//! still shows as a bar (bars start at ½, below the first tick at 1), and the bulk keeps its
//! shape. Each panel also prints the threshold counts, so nothing depends on reading bar heights.
//!
//! plotters is built without its `ttf` feature: the SVG backend writes `<text>` elements itself
//! (the viewer picks the font), and the layout uses plotters' built-in size estimate, so no font
//! files are needed.

use std::io::Write as _;
use std::path::Path;

use anyhow::Result;
use biotet::quality::{Histogram, QualityReport, REGULAR_SOLID_ANGLE, TriQualityReport};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Size of the whole picture, in pixels.
const SIZE: (u32, u32) = (1200, 540);
const FONT: &str = "sans-serif";
const BAR: RGBColor = RGBColor(70, 110, 170);
const LOW: RGBColor = RGBColor(200, 30, 30);
const HIGH: RGBColor = RGBColor(230, 120, 0);
const REFERENCE: RGBColor = RGBColor(20, 140, 60);
/// The bottom of every bar on the log axis: below 1, so a bin holding one element shows.
const FLOOR: f64 = 0.5;

/// What one histogram panel shows.
struct Panel<'a> {
    caption: String,
    x_desc: &'a str,
    hist: &'a Histogram,
    /// The x range shown.
    x_range: (f64, f64),
    /// Label every this many x units.
    x_step: f64,
    /// Vertical dashed lines: (x, label, colour).
    marks: Vec<(f64, String, RGBColor)>,
    /// Legend entries for the mark colours: (label, colour).
    legend: Vec<(String, RGBColor)>,
    /// Lines of text in the top-left corner.
    notes: Vec<String>,
}

/// Draw the dihedral- and solid-angle histograms of a tet mesh's report to an SVG file at `path`
/// (written to a temporary file next to it, then renamed). `title` heads the picture, e.g. the
/// mesh's file name.
pub fn write_quality_svg(report: &QualityReport, path: &Path, title: &str) -> Result<()> {
    write_svg(path, &quality_svg(report, title)?)
}

/// The SVG text of [`write_quality_svg`].
pub fn quality_svg(report: &QualityReport, title: &str) -> Result<String> {
    let r = report;
    let regular_dihedral = (1.0f64 / 3.0).acos().to_degrees();
    let mut notes = vec![format!(
        "min {}  max {}  ({} tets)",
        deg(r.min_dihedral_deg),
        deg(r.max_dihedral_deg),
        r.n_tets
    )];
    notes.push(format!(
        "tets with min dihedral <5°: {}  <10°: {}  <20°: {}",
        r.n_dihedral_lt_5, r.n_dihedral_lt_10, r.n_dihedral_lt_20
    ));
    notes.push(format!(
        "tets with max dihedral >160°: {}  >170°: {}  >175°: {}",
        r.n_dihedral_gt_160, r.n_dihedral_gt_170, r.n_dihedral_gt_175
    ));
    let dihedral = Panel {
        caption: "Dihedral angles (6 per tet, 10° bins)".into(),
        x_desc: "dihedral angle (degrees)",
        hist: &r.dihedral_histogram,
        x_range: (0.0, 180.0),
        x_step: 20.0,
        marks: angle_marks(Some((regular_dihedral, "70.5°"))),
        legend: angle_legend(Some("regular tet 70.53°")),
        notes,
    };

    let h = &r.solid_angle_histogram;
    let x_hi = solid_x_hi(&[h]);
    let mut notes = vec![format!(
        "min {}  max {}  mean {}",
        sr(r.min_solid_angle_sr),
        sr(r.max_solid_angle_sr),
        sr(r.mean_solid_angle_sr)
    )];
    if h.below > 0 {
        notes.push(format!(
            "{} negative solid angles (inverted tets) not shown",
            h.below
        ));
    }
    notes.push(format!("inverted tets (volume <= 0): {}", r.n_inverted));
    let solid = Panel {
        caption: "Solid angles (4 per tet, 0.05 sr bins)".into(),
        x_desc: "solid angle (steradians)",
        hist: h,
        x_range: (0.0, x_hi),
        x_step: if x_hi > 3.0 { 0.5 } else { 0.25 },
        marks: vec![(
            REGULAR_SOLID_ANGLE,
            format!("{REGULAR_SOLID_ANGLE:.4}"),
            REFERENCE,
        )],
        legend: vec![(
            format!("regular tet {REGULAR_SOLID_ANGLE:.4} sr"),
            REFERENCE,
        )],
        notes,
    };
    render(title, [&dihedral, &solid], draw_panel)
}

/// Draw the angle and minimum-angle histograms of a 2D triangle mesh's report to an SVG file at
/// `path` (written to a temporary file next to it, then renamed). `title` heads the picture.
pub fn write_tri_quality_svg(report: &TriQualityReport, path: &Path, title: &str) -> Result<()> {
    write_svg(path, &tri_quality_svg(report, title)?)
}

/// The SVG text of [`write_tri_quality_svg`].
pub fn tri_quality_svg(report: &TriQualityReport, title: &str) -> Result<String> {
    let r = report;
    let angles = Panel {
        caption: "Angles (3 per triangle, 10° bins)".into(),
        x_desc: "angle (degrees)",
        hist: &r.angle_histogram,
        x_range: (0.0, 180.0),
        x_step: 20.0,
        marks: angle_marks(Some((60.0, "60°"))),
        legend: angle_legend(Some("equilateral 60°")),
        notes: vec![
            format!(
                "min {}  max {}  ({} triangles)",
                deg(r.min_angle_deg),
                deg(r.max_angle_deg),
                r.n_triangles
            ),
            format!(
                "triangles with max angle >160°: {}  >170°: {}  >175°: {}",
                r.n_angle_gt_160, r.n_angle_gt_170, r.n_angle_gt_175
            ),
            format!("inverted triangles (area <= 0): {}", r.n_inverted),
        ],
    };
    let mut marks = angle_marks(Some((60.0, "60°")));
    marks.retain(|m| m.0 <= 90.0);
    let mut legend = angle_legend(Some("equilateral 60°"));
    legend.retain(|l| l.1 != HIGH);
    let min_angles = Panel {
        caption: "Smallest angle of each triangle (5° bins)".into(),
        x_desc: "smallest angle (degrees)",
        hist: &r.min_angle_histogram,
        x_range: (0.0, 90.0),
        x_step: 10.0,
        marks,
        legend,
        notes: vec![
            format!("mean {}", deg(r.mean_min_angle_deg)),
            format!(
                "triangles with min angle <5°: {}  <10°: {}  <20°: {}",
                r.n_angle_lt_5, r.n_angle_lt_10, r.n_angle_lt_20
            ),
        ],
    };
    render(title, [&angles, &min_angles], draw_panel)
}

/// The SVG text of the dihedral- and solid-angle histograms of a mesh before and after
/// smoothing, overlaid (before as a grey outline, after as filled bars; dissertation figs. 4.8
/// and 4.9). `below_02` is the share of solid angles under 0.2 sr before and after.
pub fn smooth_svg(
    before: &QualityReport,
    after: &QualityReport,
    below_02: (f64, f64),
    title: &str,
) -> Result<String> {
    let regular_dihedral = (1.0f64 / 3.0).acos().to_degrees();
    let dihedral = Overlay {
        caption: "Dihedral angles before and after (10° bins)".into(),
        x_desc: "dihedral angle (degrees)",
        before: &before.dihedral_histogram,
        after: &after.dihedral_histogram,
        x_range: (0.0, 180.0),
        x_step: 20.0,
        reference: (regular_dihedral, format!("regular {regular_dihedral:.2}°")),
        notes: vec![
            format!(
                "min {} → {}   max {} → {}",
                deg(before.min_dihedral_deg),
                deg(after.min_dihedral_deg),
                deg(before.max_dihedral_deg),
                deg(after.max_dihedral_deg)
            ),
            format!(
                "tets with min dihedral <10°: {} → {}   <20°: {} → {}",
                before.n_dihedral_lt_10,
                after.n_dihedral_lt_10,
                before.n_dihedral_lt_20,
                after.n_dihedral_lt_20
            ),
        ],
    };
    let hb = &before.solid_angle_histogram;
    let ha = &after.solid_angle_histogram;
    let x_hi = solid_x_hi(&[hb, ha]);
    let solid = Overlay {
        caption: "Solid angles before and after (0.05 sr bins)".into(),
        x_desc: "solid angle (steradians)",
        before: hb,
        after: ha,
        x_range: (0.0, x_hi),
        x_step: if x_hi > 3.0 { 0.5 } else { 0.25 },
        reference: (
            REGULAR_SOLID_ANGLE,
            format!("regular {REGULAR_SOLID_ANGLE:.4} sr"),
        ),
        notes: vec![
            format!(
                "min {} → {}",
                sr(before.min_solid_angle_sr),
                sr(after.min_solid_angle_sr)
            ),
            format!(
                "share of solid angles < 0.2 sr: {:.2}% → {:.2}%",
                100.0 * below_02.0,
                100.0 * below_02.1
            ),
        ],
    };
    render(title, [&dihedral, &solid], draw_overlay)
}

/// One panel of [`smooth_svg`]: two histograms with the same bins.
struct Overlay<'a> {
    caption: String,
    x_desc: &'a str,
    before: &'a Histogram,
    after: &'a Histogram,
    x_range: (f64, f64),
    x_step: f64,
    reference: (f64, String),
    notes: Vec<String>,
}

fn draw_overlay(area: &Area, p: &Overlay) -> Result<()> {
    let body = draw_head(area, &p.caption, &p.notes)?;
    let (x0, x1) = p.x_range;
    let peak = [p.before, p.after]
        .iter()
        .flat_map(|h| h.counts.iter().copied())
        .max()
        .unwrap_or(0)
        .max(1) as f64;
    let y_hi = peak * 1000.0;
    let mut chart = log_chart(&body, p.x_range, p.x_step, p.x_desc, y_hi)?;
    chart
        .draw_series(bars(p.after, x1).map(|r| Rectangle::new(r, BAR.mix(0.6).filled())))?
        .label(format!("after ({} values)", p.after.total()))
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], BAR.mix(0.6).filled()));
    let grey = RGBColor(60, 60, 60);
    chart
        .draw_series(bars(p.before, x1).map(|r| Rectangle::new(r, grey.stroke_width(2))))?
        .label(format!("before ({} values)", p.before.total()))
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], grey.stroke_width(2)));
    let (rx, rl) = (&p.reference.0, &p.reference.1);
    if *rx >= x0 && *rx <= x1 {
        chart
            .draw_series(DashedLineSeries::new(
                [(*rx, FLOOR), (*rx, y_hi)],
                6,
                4,
                REFERENCE.stroke_width(2),
            ))?
            .label(rl.clone())
            .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], REFERENCE.stroke_width(2)));
    }
    draw_legend(&mut chart)
}

/// `x` with `prec` decimals, more for a small value (three significant digits), scientific
/// below 0.001.
fn num(x: f64, prec: usize) -> String {
    let a = x.abs();
    if a > 0.0 && a < 1e-3 {
        return format!("{x:.2e}");
    }
    let prec = if a > 0.0 && a < 1.0 {
        prec.max((-a.log10()).floor() as usize + 3)
    } else {
        prec
    };
    format!("{x:.prec$}")
}

/// `12.34°` or `-`.
fn deg(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), |x| format!("{}°", num(x, 2)))
}

/// `0.1234 sr` or `-`.
fn sr(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), |x| format!("{} sr", num(x, 4)))
}

/// The threshold lines of an angle histogram, plus an optional reference angle.
fn angle_marks(reference: Option<(f64, &str)>) -> Vec<(f64, String, RGBColor)> {
    let mut v: Vec<(f64, String, RGBColor)> = [5.0, 10.0, 20.0]
        .iter()
        .map(|&x| (x, format!("{x}"), LOW))
        .chain(
            [160.0, 170.0, 175.0]
                .iter()
                .map(|&x| (x, format!("{x}"), HIGH)),
        )
        .collect();
    if let Some((x, label)) = reference {
        v.push((x, label.to_string(), REFERENCE));
    }
    v
}

fn angle_legend(reference: Option<&str>) -> Vec<(String, RGBColor)> {
    let mut v = vec![
        ("5°, 10°, 20° (small angles)".to_string(), LOW),
        ("160°, 170°, 175° (large angles)".to_string(), HIGH),
    ];
    if let Some(r) = reference {
        v.push((r.to_string(), REFERENCE));
    }
    v
}

/// 1, 10, 100, 1k, 10k, 100k, 1M, …
fn count_label(y: f64) -> String {
    let y = y.round();
    match y {
        y if y >= 1e9 => format!("{}G", y / 1e9),
        y if y >= 1e6 => format!("{}M", y / 1e6),
        y if y >= 1e3 => format!("{}k", y / 1e3),
        y => format!("{y}"),
    }
}

/// One half of the picture.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A chart with a linear x axis and a log count axis.
type LogChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, LogCoord<f64>>>;

/// Render two panels side by side under `title` into an SVG string, each with `draw`.
fn render<P>(title: &str, panels: [&P; 2], draw: fn(&Area, &P) -> Result<()>) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(title, (FONT, 24).into_font().color(&BLACK))?;
        let (left, right) = root.split_horizontally(SIZE.0 / 2);
        draw(&left, panels[0])?;
        draw(&right, panels[1])?;
        root.present()?;
    }
    Ok(svg)
}

/// Draw `caption` and the `notes` at the top of `area`; the rest of it, for the plot.
fn draw_head<'a>(area: &Area<'a>, caption: &str, notes: &[String]) -> Result<Area<'a>> {
    let line = 16;
    let (head, body) = area.split_vertically(34 + line * notes.len() as i32);
    head.draw(&Text::new(
        caption.to_string(),
        (68, 8),
        (FONT, 18).into_font().color(&BLACK),
    ))?;
    for (i, note) in notes.iter().enumerate() {
        head.draw(&Text::new(
            note.clone(),
            (68, 32 + line * i as i32),
            (FONT, 13).into_font().color(&BLACK.mix(0.85)),
        ))?;
    }
    Ok(body)
}

/// The chart of a histogram panel on `body`: `x_range` labelled every `x_step`, counts on a log
/// axis from [`FLOOR`] to `y_hi`, axes and grid drawn.
fn log_chart<'a, 'b>(
    body: &'a Area<'b>,
    (x0, x1): (f64, f64),
    x_step: f64,
    x_desc: &str,
    y_hi: f64,
) -> Result<LogChart<'a, 'b>> {
    let mut chart = ChartBuilder::on(body)
        .margin(12)
        .margin_top(4)
        .x_label_area_size(44)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, (FLOOR..y_hi).log_scale())?;
    let n_x_labels = ((x1 - x0) / x_step).round() as usize + 1;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n_x_labels)
        .y_labels(12)
        .x_label_formatter(&|x| {
            let s = format!("{x:.2}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        })
        .y_label_formatter(&|y| count_label(*y))
        .x_desc(x_desc)
        .y_desc("count (log scale)")
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .light_line_style(WHITE)
        .bold_line_style(BLACK.mix(0.12))
        .draw()?;
    Ok(chart)
}

/// The bars of the non-empty bins of `h` starting below `x1` (cut at `x1`), from [`FLOOR`] up.
fn bars(h: &Histogram, x1: f64) -> impl Iterator<Item = [(f64, f64); 2]> + '_ {
    (0..h.counts.len()).filter_map(move |i| {
        let (lo, hi, c) = (h.bin_lo(i), h.bin_hi(i), h.counts[i]);
        (c > 0 && lo < x1).then_some([(lo, FLOOR), (hi.min(x1), c as f64)])
    })
}

/// The legend box in the upper right corner.
fn draw_legend<'a, 'b: 'a>(chart: &mut LogChart<'a, 'b>) -> Result<()> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 12))
        .background_style(WHITE)
        .border_style(BLACK.mix(0.4))
        .draw()?;
    Ok(())
}

/// The upper end of a solid-angle axis for histograms `hs` (same bins): up to the last non-empty
/// bin, at least 1 sr, in whole 0.5 sr steps. Solid angles above ~2 sr are rare and the full
/// [0, 6.3] range would squeeze the bulk into a corner.
fn solid_x_hi(hs: &[&Histogram]) -> f64 {
    let last = hs
        .iter()
        .filter_map(|h| h.occupied().map(|o| h.bin_hi(*o.end())))
        .fold(0.0, f64::max);
    (last.max(1.0) * 2.0).ceil() / 2.0
}

fn draw_panel(area: &Area, p: &Panel) -> Result<()> {
    let body = draw_head(area, &p.caption, &p.notes)?;
    let (x0, x1) = p.x_range;
    let peak = p.hist.counts.iter().copied().max().unwrap_or(0).max(1) as f64;
    // Three decades of headroom above the tallest bar for the mark labels and the legend.
    let y_hi = peak * 1000.0;
    let mut chart = log_chart(&body, p.x_range, p.x_step, p.x_desc, y_hi)?;

    let h = p.hist;
    chart
        .draw_series(bars(h, x1).map(|r| Rectangle::new(r, BAR.mix(0.75).filled())))?
        .label(format!("count ({} values)", h.total()))
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], BAR.mix(0.75).filled()));
    chart.draw_series(bars(h, x1).map(|r| Rectangle::new(r, BAR.stroke_width(1))))?;

    // Threshold and reference lines, labelled a little above the tallest bar.
    for (x, label, color) in &p.marks {
        if *x < x0 || *x > x1 {
            continue;
        }
        chart.draw_series(DashedLineSeries::new(
            [(*x, FLOOR), (*x, y_hi)],
            6,
            4,
            color.stroke_width(2),
        ))?;
        // Reading upwards, just right of the line.
        let style = (FONT, 11)
            .into_font()
            .color(color)
            .transform(FontTransform::Rotate270);
        chart.draw_series(std::iter::once(
            EmptyElement::at((*x, peak * 3.0)) + Text::new(label.clone(), (3, 0), style),
        ))?;
    }
    for (label, color) in &p.legend {
        let c = *color;
        chart
            .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 14, y)], c.stroke_width(2)));
    }
    draw_legend(&mut chart)
}

/// Write through a temporary file in the target's directory and rename it into place, so the
/// target is either the old file or the whole new one.
fn write_svg(path: &Path, svg: &str) -> Result<()> {
    biotet_io::atomic::write_atomic(path, |w| {
        w.write_all(svg.as_bytes())
            .map_err(|e| biotet_io::Error::io(&path.display().to_string(), e))
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use biotet::{TetMesh, TriMesh};

    /// A small check that `text` is well-formed XML: every tag closed in order, attribute values
    /// quoted, no stray `<` or unescaped `&` in text or attributes.
    fn assert_well_formed(text: &str) {
        let mut stack: Vec<&str> = Vec::new();
        let mut rest = text;
        let check_text = |t: &str| {
            for (i, _) in t.match_indices('&') {
                let ent = &t[i..t[i..].find(';').map_or(t.len(), |j| i + j + 1)];
                assert!(
                    ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"].contains(&ent)
                        || ent.starts_with("&#"),
                    "bad entity {ent:?}"
                );
            }
            assert!(
                !t.contains('>') || !t.contains('<'),
                "stray markup in {t:?}"
            );
        };
        while let Some(open) = rest.find('<') {
            check_text(&rest[..open]);
            let close = rest[open..].find('>').expect("unclosed tag") + open;
            let tag = &rest[open + 1..close];
            rest = &rest[close + 1..];
            if tag.starts_with('?') || tag.starts_with('!') {
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop(), Some(name.trim()), "mismatched </{name}>");
                continue;
            }
            let self_closing = tag.ends_with('/');
            let body = tag.trim_end_matches('/');
            let name = body.split_whitespace().next().expect("a tag name");
            // Attributes: name="value" pairs.
            let mut attrs = body[name.len()..].trim();
            while !attrs.is_empty() {
                let eq = attrs.find('=').expect("attribute without value");
                assert!(
                    attrs[eq + 1..].starts_with('"'),
                    "unquoted attribute in <{tag}>"
                );
                let end = attrs[eq + 2..].find('"').expect("unterminated value") + eq + 2;
                check_text(&attrs[eq + 2..end]);
                assert!(!attrs[eq + 2..end].contains('<'));
                attrs = attrs[end + 1..].trim_start();
            }
            if !self_closing {
                stack.push(name);
            }
        }
        check_text(rest);
        assert!(stack.is_empty(), "unclosed elements {stack:?}");
    }

    /// A regular tet, a sliver and an inverted tet.
    fn mesh() -> TetMesh {
        let h = 0.01;
        let points = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [11.0, 0.0, h],
            [9.0, 0.0, h],
            [10.0, 1.0, -h],
            [10.0, -1.0, -h],
        ];
        TetMesh::new(
            points,
            vec![[0, 1, 2, 3], [4, 5, 6, 7], [0, 2, 1, 3]],
            vec![1, 2, 2],
        )
    }

    #[test]
    fn tet_svg_is_well_formed_and_labelled() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("q.svg");
        std::fs::write(&path, "old contents").unwrap();
        let report = QualityReport::of(&mesh());
        write_quality_svg(&report, &path, "brain <v2> & co.vtu").unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_well_formed(&svg);
        for label in [
            "brain &lt;v2&gt; &amp; co.vtu",
            "Dihedral angles",
            "Solid angles",
            "dihedral angle (degrees)",
            "solid angle (steradians)",
            "count (log scale)",
            "5°, 10°, 20°",
            "160°, 170°, 175°",
            "regular tet 0.5513 sr",
            "regular tet 70.53°",
            "&lt;5°: 1",
            "&gt;175°: 1",
            "inverted tets (volume &lt;= 0): 1",
            "4 negative solid angles",
        ] {
            assert!(svg.contains(label), "{label:?} missing");
        }
        // Replaced whole, and no temporary file left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
        // Same report, same bytes.
        let again = dir.path().join("again.svg");
        write_quality_svg(&report, &again, "brain <v2> & co.vtu").unwrap();
        assert_eq!(std::fs::read(&again).unwrap(), svg.as_bytes());
    }

    #[test]
    fn empty_meshes_plot_too() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty.svg");
        write_quality_svg(&QualityReport::of(&TetMesh::default()), &path, "empty").unwrap();
        assert_well_formed(&std::fs::read_to_string(&path).unwrap());
        write_tri_quality_svg(&TriQualityReport::of(&TriMesh::default()), &path, "empty").unwrap();
        assert_well_formed(&std::fs::read_to_string(&path).unwrap());
    }

    #[test]
    fn tri_svg_is_well_formed_and_labelled() {
        let s3 = 3f64.sqrt();
        let mesh = TriMesh::new(
            vec![
                [0.0, 0.0],
                [1.0, 0.0],
                [0.5, s3 / 2.0],
                [3.0, 0.0],
                [4.0, 0.0],
                [3.5, 0.01],
            ],
            vec![[0, 1, 2], [3, 4, 5]],
            vec![1, 1],
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tri.svg");
        write_tri_quality_svg(&TriQualityReport::of(&mesh), &path, "square.node").unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert_well_formed(&svg);
        for label in [
            "square.node",
            "Angles (3 per triangle",
            "Smallest angle of each triangle",
            "equilateral 60°",
            "&lt;5°: 1",
            "&gt;175°: 1",
        ] {
            assert!(svg.contains(label), "{label:?} missing");
        }
    }

    #[test]
    fn a_missing_directory_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/q.svg");
        let err = write_quality_svg(&QualityReport::of(&mesh()), &path, "t").unwrap_err();
        assert!(format!("{err:#}").contains("q.svg"), "{err:#}");
    }

    /// The JSON keys docs/commands.md and the CLI document, present in both reports.
    #[test]
    fn json_keys() {
        let j = serde_json::to_value(QualityReport::of(&mesh())).unwrap();
        for k in [
            "n_points",
            "n_tets",
            "n_regions",
            "volume",
            "min_dihedral_deg",
            "max_dihedral_deg",
            "mean_dihedral_deg",
            "min_solid_angle_sr",
            "max_solid_angle_sr",
            "mean_solid_angle_sr",
            "mean_q",
            "min_q",
            "max_q",
            "min_radius_ratio",
            "mean_radius_ratio",
            "n_dihedral_lt_5",
            "n_dihedral_lt_10",
            "n_dihedral_lt_20",
            "n_dihedral_gt_160",
            "n_dihedral_gt_170",
            "n_dihedral_gt_175",
            "n_inverted",
            "dihedral_histogram",
            "solid_angle_histogram",
            "min_dihedral_histogram",
            "worst_tets",
            "regions",
        ] {
            assert!(j.get(k).is_some(), "missing {k}");
        }
        assert_eq!(j["n_inverted"], 1);
        assert_eq!(j["n_dihedral_lt_5"], 1);
        assert_eq!(
            j["dihedral_histogram"]["counts"].as_array().unwrap().len(),
            18
        );
        assert_eq!(j["worst_tets"][0]["tet"], 1);
        let region = &j["regions"][1];
        for k in [
            "label",
            "n_tets",
            "volume",
            "min_dihedral_deg",
            "max_dihedral_deg",
            "min_solid_angle_sr",
            "min_q",
        ] {
            assert!(region.get(k).is_some(), "missing regions[].{k}");
        }
        // An empty mesh: nulls, no NaN (serde_json would refuse or print null for NaN anyway;
        // check the values are genuinely absent rather than NaN).
        let e = QualityReport::of(&TetMesh::default());
        assert!(e.min_q.is_none());
        let j = serde_json::to_string(&e).unwrap();
        assert!(
            j.contains("\"min_dihedral_deg\":null") && j.contains("\"volume\":0.0"),
            "{j}"
        );

        let t = serde_json::to_value(TriQualityReport::of(&TriMesh::default())).unwrap();
        for k in [
            "n_points",
            "n_triangles",
            "n_regions",
            "area",
            "min_angle_deg",
            "max_angle_deg",
            "mean_angle_deg",
            "min_q",
            "mean_q",
            "n_angle_lt_5",
            "n_angle_gt_175",
            "n_inverted",
            "angle_histogram",
            "worst_triangles",
            "regions",
        ] {
            assert!(t.get(k).is_some(), "missing {k}");
        }
    }
}
