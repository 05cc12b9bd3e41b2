//! A [`Scene`] as SVG text: one `<polygon>` per cut tet or face, `<line>`s on top, the key
//! on the right. Coordinates with two decimals (a hundredth of a pixel).

use super::{Key, Layout, Rgb, Scene, short};
use std::fmt::Write;

fn hex(c: Rgb) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The SVG document of `scene` on a page `width` pixels wide.
pub fn render(scene: &Scene, width: u32) -> String {
    let l = Layout::fit(scene, width);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="13">"#,
        w = l.width,
        h = l.height
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    if !scene.title.is_empty() {
        let _ = writeln!(s, r#"<text x="16" y="20">{}</text>"#, esc(&scene.title));
    }
    // Thin outlines: at the scale of a million-tet mesh they would hide the fill.
    let stroke_w = (0.25 * l.scale).clamp(0.1, 0.6);
    let _ = writeln!(
        s,
        r#"<g stroke-width="{stroke_w:.2}" stroke-linejoin="round">"#
    );
    for p in &scene.polygons {
        let pts: Vec<String> = p
            .points
            .iter()
            .map(|&q| {
                let [x, y] = l.px(q);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let stroke = p
            .stroke
            .map_or(String::new(), |c| format!(r#" stroke="{}""#, hex(c)));
        let _ = writeln!(
            s,
            r#"<polygon points="{}" fill="{}"{stroke}/>"#,
            pts.join(" "),
            hex(p.fill)
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, r#"<g stroke-linecap="round">"#);
    for g in &scene.segments {
        let [a, b] = g.ends.map(|q| l.px(q));
        let _ = writeln!(
            s,
            r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{}" stroke-width="{}"/>"#,
            a[0],
            a[1],
            b[0],
            b[1],
            hex(g.color),
            g.width
        );
    }
    let _ = writeln!(s, "</g>");
    key(&mut s, &scene.key, &l);
    s.push_str("</svg>\n");
    s
}

fn key(s: &mut String, key: &Key, l: &Layout) {
    let x = l.key_x;
    let top = 48.0;
    match key {
        Key::Labels(items) => {
            let _ = writeln!(s, r#"<text x="{x:.1}" y="{:.1}">label</text>"#, top - 8.0);
            for (i, (label, c)) in items.iter().enumerate() {
                let y = top + 20.0 * i as f64;
                let _ = writeln!(
                    s,
                    r#"<rect x="{x:.1}" y="{y:.1}" width="14" height="14" fill="{}" stroke="black" stroke-width="0.5"/><text x="{:.1}" y="{:.1}">{label}</text>"#,
                    hex(*c),
                    x + 20.0,
                    y + 12.0
                );
            }
        }
        Key::Bar {
            range,
            ticks,
            title,
        } => {
            let h = (f64::from(l.height) - top - 40.0).clamp(60.0, 300.0);
            let _ = writeln!(
                s,
                r#"<text x="{x:.1}" y="{:.1}">{}</text>"#,
                top - 8.0,
                esc(title)
            );
            let steps = 64;
            for i in 0..steps {
                let t0 = i as f64 / steps as f64;
                let c = super::palette::ramp(1.0 - t0);
                let _ = writeln!(
                    s,
                    r#"<rect x="{x:.1}" y="{:.2}" width="16" height="{:.2}" fill="{}"/>"#,
                    top + t0 * h,
                    h / steps as f64 + 0.5,
                    hex(c)
                );
            }
            for &t in ticks {
                let y = top + (1.0 - (t - range[0]) / (range[1] - range[0])) * h;
                let _ = writeln!(
                    s,
                    r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black"/><text x="{:.1}" y="{:.1}">{}</text>"#,
                    x + 16.0,
                    x + 20.0,
                    x + 24.0,
                    y + 4.0,
                    short(t)
                );
            }
        }
    }
}
