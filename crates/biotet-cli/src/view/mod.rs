//! `biotet view`: pictures of a mesh with no GPU and no external renderer.
//!
//! A picture is built as a [`Scene`] in the plane of the drawing (filled convex polygons,
//! line segments, a legend or a colour bar) by [`section`] (the tets a plane cuts, as their
//! cross-section polygons) or [`iso`] (the boundary surface, shaded, back to front), then written
//! by [`svg`] or [`raster`] (PNG). Everything is computed in a fixed order, so the same mesh and
//! options give the same bytes.

pub mod iso;
pub mod palette;
pub mod raster;
pub mod section;
pub mod svg;

/// An 8-bit RGB colour.
pub type Rgb = [u8; 3];

/// A filled convex polygon with an optional outline.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    /// Corners in drawing coordinates (x right, y up), in order around the polygon.
    pub points: Vec<[f64; 2]>,
    /// Fill colour.
    pub fill: Rgb,
    /// Outline colour, if drawn.
    pub stroke: Option<Rgb>,
}

/// A line segment in drawing coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// End points.
    pub ends: [[f64; 2]; 2],
    /// Colour.
    pub color: Rgb,
    /// Width in pixels.
    pub width: f64,
}

/// What explains the colours.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// One swatch per label value.
    Labels(Vec<(u32, Rgb)>),
    /// A colour bar over a range of values (smallest dihedral angle, degrees).
    Bar {
        /// The values at the bar's ends.
        range: [f64; 2],
        /// Tick values.
        ticks: Vec<f64>,
        /// What the values are.
        title: String,
    },
}

/// A picture before it is written: polygons first (in drawing order), then segments on top.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Filled polygons, drawn in order (later ones cover earlier ones).
    pub polygons: Vec<Polygon>,
    /// Line segments, drawn after the polygons.
    pub segments: Vec<Segment>,
    /// The colour key.
    pub key: Key,
    /// A line of text above the picture (SVG only: the PNG has no font for words).
    pub title: String,
}

impl Scene {
    /// The bounding box of everything drawn, as `[xmin, ymin, xmax, ymax]`; a unit box when
    /// the scene is empty.
    pub fn bounds(&self) -> [f64; 4] {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        let pts = self
            .polygons
            .iter()
            .flat_map(|p| p.points.iter())
            .chain(self.segments.iter().flat_map(|s| s.ends.iter()));
        for p in pts {
            b[0] = b[0].min(p[0]);
            b[1] = b[1].min(p[1]);
            b[2] = b[2].max(p[0]);
            b[3] = b[3].max(p[1]);
        }
        if b[0] > b[2] {
            return [0.0, 0.0, 1.0, 1.0];
        }
        if b[2] - b[0] == 0.0 {
            b[2] = b[0] + 1.0;
        }
        if b[3] - b[1] == 0.0 {
            b[3] = b[1] + 1.0;
        }
        b
    }
}

/// Where the picture goes on the page: `width` × `height` pixels, the scene fitted into the
/// left part with a margin, the key on the right.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    /// Page width in pixels.
    pub width: u32,
    /// Page height in pixels.
    pub height: u32,
    /// Scene coordinates to page pixels: `(x, y) -> (x0 + s·x, y0 − s·y)`.
    pub scale: f64,
    /// See `scale`.
    pub x0: f64,
    /// See `scale`.
    pub y0: f64,
    /// Left edge of the key.
    pub key_x: f64,
}

/// Room at the top for the title, at the sides for the margin and on the right for the key.
const MARGIN: f64 = 16.0;
const TITLE: f64 = 28.0;
const KEY: f64 = 120.0;

impl Layout {
    /// The layout of `scene` on a page `width` pixels wide (the height follows the scene's
    /// aspect ratio).
    pub fn fit(scene: &Scene, width: u32) -> Layout {
        let [x0, y0, x1, y1] = scene.bounds();
        let avail = (f64::from(width) - 2.0 * MARGIN - KEY).max(16.0);
        let scale = avail / (x1 - x0);
        let height = ((y1 - y0) * scale + 2.0 * MARGIN + TITLE).ceil().max(200.0);
        Layout {
            width,
            height: height as u32,
            scale,
            x0: MARGIN - x0 * scale,
            y0: TITLE + MARGIN + y1 * scale,
            key_x: MARGIN + avail + 16.0,
        }
    }

    /// A scene point on the page.
    pub fn px(&self, p: [f64; 2]) -> [f64; 2] {
        [self.x0 + self.scale * p[0], self.y0 - self.scale * p[1]]
    }
}

/// Short number for keys and ticks: integers without a fraction.
pub fn short(x: f64) -> String {
    if x == x.round() && x.abs() < 1e9 {
        format!("{}", x as i64)
    } else {
        format!("{x:.1}")
    }
}
