//! A [`Scene`] as a PNG: convex polygons filled by scanlines at pixel centres on a grid twice
//! as fine, averaged down (anti-aliasing), encoded by the `png` crate. The key's numbers use a
//! 3×5 digit font of our own: the PNG has no other text (the SVG has the title and words).

use super::{Key, Layout, Rgb, Scene, short};

/// Supersampling factor per axis.
const SS: usize = 2;

struct Canvas {
    w: usize,
    h: usize,
    px: Vec<Rgb>,
}

impl Canvas {
    fn new(w: usize, h: usize) -> Canvas {
        Canvas {
            w,
            h,
            px: vec![[255, 255, 255]; w * h],
        }
    }

    /// Fill the convex polygon `pts` (canvas pixels): every pixel whose centre is inside or on
    /// its edges.
    fn fill_convex(&mut self, pts: &[[f64; 2]], c: Rgb) {
        if pts.len() < 3 {
            return;
        }
        let ymin = pts.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let ymax = pts.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let y0 = (ymin - 0.5).ceil().max(0.0) as usize;
        let y1 = ((ymax - 0.5).floor() as i64).min(self.h as i64 - 1);
        for y in y0 as i64..=y1 {
            let yc = y as f64 + 0.5;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..pts.len() {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                if (a[1] <= yc && b[1] >= yc) || (b[1] <= yc && a[1] >= yc) {
                    let x = if a[1] == b[1] {
                        lo = lo.min(a[0].min(b[0]));
                        a[0].max(b[0])
                    } else {
                        a[0] + (yc - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
                    };
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
            }
            if lo > hi {
                continue;
            }
            let x0 = (lo - 0.5).ceil().max(0.0) as usize;
            let x1 = ((hi - 0.5).floor() as i64).min(self.w as i64 - 1);
            if x1 < x0 as i64 {
                continue;
            }
            let row = y as usize * self.w;
            for x in x0..=x1 as usize {
                self.px[row + x] = c;
            }
        }
    }

    /// A segment of width `w` as the quadrilateral around it.
    fn line(&mut self, a: [f64; 2], b: [f64; 2], w: f64, c: Rgb) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = (dx * dx + dy * dy).sqrt();
        if l == 0.0 {
            return;
        }
        let (nx, ny) = (-dy / l * w / 2.0, dx / l * w / 2.0);
        self.fill_convex(
            &[
                [a[0] + nx, a[1] + ny],
                [b[0] + nx, b[1] + ny],
                [b[0] - nx, b[1] - ny],
                [a[0] - nx, a[1] - ny],
            ],
            c,
        );
    }

    fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, c: Rgb) {
        self.fill_convex(&[[x, y], [x + w, y], [x + w, y + h], [x, y + h]], c);
    }

    /// `text` (digits, '.', '-'; other characters leave a gap) with its top left at `(x, y)`,
    /// each font pixel `s` canvas pixels.
    fn text(&mut self, x: f64, y: f64, text: &str, s: f64) {
        for (i, ch) in text.chars().enumerate() {
            let Some(rows) = glyph(ch) else { continue };
            let gx = x + i as f64 * 4.0 * s;
            for (r, bits) in rows.iter().enumerate() {
                for k in 0..3 {
                    if bits >> (2 - k) & 1 == 1 {
                        self.rect(gx + k as f64 * s, y + r as f64 * s, s, s, [0, 0, 0]);
                    }
                }
            }
        }
    }

    /// Average `SS`×`SS` blocks.
    fn downsample(&self) -> (usize, usize, Vec<u8>) {
        let (w, h) = (self.w / SS, self.h / SS);
        let mut out = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0u32; 3];
                for dy in 0..SS {
                    for dx in 0..SS {
                        let p = self.px[(y * SS + dy) * self.w + x * SS + dx];
                        for k in 0..3 {
                            acc[k] += u32::from(p[k]);
                        }
                    }
                }
                let n = (SS * SS) as u32;
                out.extend(acc.map(|v| ((v + n / 2) / n) as u8));
            }
        }
        (w, h, out)
    }
}

/// Rows of a 3×5 glyph, the high bit on the left.
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b001, 0b001, 0b001],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        _ => return None,
    })
}

/// The PNG file of `scene` on a page `width` pixels wide.
pub fn render(scene: &Scene, width: u32) -> Result<Vec<u8>, png::EncodingError> {
    let l = Layout::fit(scene, width);
    let ss = SS as f64;
    let mut cv = Canvas::new(l.width as usize * SS, l.height as usize * SS);
    let at = |q: [f64; 2]| {
        let [x, y] = l.px(q);
        [x * ss, y * ss]
    };
    for p in &scene.polygons {
        let pts: Vec<[f64; 2]> = p.points.iter().map(|&q| at(q)).collect();
        cv.fill_convex(&pts, p.fill);
        if let Some(c) = p.stroke {
            let w = (0.25 * l.scale).clamp(0.1, 0.6) * ss;
            for i in 0..pts.len() {
                cv.line(pts[i], pts[(i + 1) % pts.len()], w, c);
            }
        }
    }
    for g in &scene.segments {
        cv.line(at(g.ends[0]), at(g.ends[1]), g.width * ss, g.color);
    }
    let (x, top) = (l.key_x * ss, 48.0 * ss);
    match &scene.key {
        Key::Labels(items) => {
            for (i, (label, c)) in items.iter().enumerate() {
                let y = top + 20.0 * ss * i as f64;
                cv.rect(x - ss, y - ss, 16.0 * ss, 16.0 * ss, [0, 0, 0]);
                cv.rect(x, y, 14.0 * ss, 14.0 * ss, *c);
                cv.text(x + 20.0 * ss, y + 2.0 * ss, &label.to_string(), 2.0 * ss);
            }
        }
        Key::Bar { range, ticks, .. } => {
            let h = (f64::from(l.height) - 48.0 - 40.0).clamp(60.0, 300.0) * ss;
            let steps = 64;
            for i in 0..steps {
                let t0 = i as f64 / steps as f64;
                cv.rect(
                    x,
                    top + t0 * h,
                    16.0 * ss,
                    h / steps as f64 + ss,
                    super::palette::ramp(1.0 - t0),
                );
            }
            for &t in ticks {
                let y = top + (1.0 - (t - range[0]) / (range[1] - range[0])) * h;
                cv.line([x + 16.0 * ss, y], [x + 20.0 * ss, y], ss, [0, 0, 0]);
                cv.text(x + 24.0 * ss, y - 5.0 * ss, &short(t), 2.0 * ss);
            }
        }
    }
    let (w, h, data) = cv.downsample();
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w as u32, h as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header()?;
        wr.write_image_data(&data)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_fills_exactly_its_pixel_centres() {
        let mut cv = Canvas::new(10, 10);
        cv.fill_convex(&[[2.0, 2.0], [6.0, 2.0], [6.0, 6.0], [2.0, 6.0]], [0, 0, 0]);
        let black = cv.px.iter().filter(|p| **p == [0, 0, 0]).count();
        assert_eq!(black, 16);
        assert_eq!(cv.px[2 * 10 + 2], [0, 0, 0]);
        assert_eq!(cv.px[6 * 10 + 6], [255, 255, 255]);
    }
}
