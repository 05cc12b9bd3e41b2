//! Exact intersection tests built from orientation predicates.
//!
//! Every decision here is a sign of [`orient3d`] (the filtered exact one) or [`orient2d`] (or an exact comparison of
//! coordinates between points already known to be collinear); floating point arithmetic is only
//! used to *prefer* a projection axis, whose validity is then verified exactly.
//!
//! Triangles are closed sets (boundary included) and must be non-degenerate (their corners not
//! collinear); the surface validator rejects degenerate triangles before using these tests. For a
//! degenerate triangle the answers are unspecified (but never a panic).
//!
//! Local numbering follows [`crate::TRI_EDGES`]: edge `k` of a triangle is the edge opposite its
//! corner `k`.

use super::filter::orient3d;
use super::predicates::{Sign, orient2d};

type P3 = [f64; 3];
type P2 = [f64; 2];

/// Where on a segment `pq` a contact point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SegPart {
    /// At the endpoint `p` (0) or `q` (1).
    Endpoint(u8),
    /// Strictly between the endpoints.
    Interior,
}

/// Where on a triangle a contact point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TriPart {
    /// At corner `k`.
    Vertex(u8),
    /// In the relative interior of edge `k` (the edge opposite corner `k`).
    Edge(u8),
    /// In the interior of the triangle.
    Interior,
}

/// How a closed segment and a closed triangle meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SegTri {
    /// They do not meet.
    Disjoint,
    /// The segment is not in the triangle's plane and crosses it at one point interior to both.
    Proper,
    /// The segment is not in the triangle's plane and meets it at one point that is an endpoint of
    /// the segment or on the triangle's boundary (or both).
    Touch {
        /// Where on the segment.
        seg: SegPart,
        /// Where on the triangle.
        tri: TriPart,
    },
    /// The segment lies in the triangle's plane and meets the triangle (at a point or along a
    /// sub-segment).
    Coplanar,
}

impl SegTri {
    /// Whether they meet at all.
    pub fn meets(self) -> bool {
        self != SegTri::Disjoint
    }
}

/// How two closed triangles meet. Shared corners are corners with exactly equal coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TriTri {
    /// They do not meet.
    Disjoint,
    /// They share exactly one corner (corner `a` of the first, `b` of the second) and meet
    /// nowhere else: legal for two triangles of a surface around a common vertex.
    SharedVertex {
        /// Corner of the first triangle.
        a: u8,
        /// Corner of the second triangle.
        b: u8,
    },
    /// They share exactly one edge (corners `a[0], a[1]` of the first equal `b[0], b[1]` of the
    /// second) and meet nowhere else: legal for two neighbouring triangles of a surface.
    SharedEdge {
        /// Corners of the first triangle.
        a: [u8; 2],
        /// Corners of the second triangle, matching `a` in order.
        b: [u8; 2],
    },
    /// Any other contact: crossing, touching at a point that is not a shared corner, coplanar
    /// overlap, or a shared corner or edge plus contact elsewhere (including identical triangles).
    Improper,
}

/// Whether triangles `t` and `u` of an indexed surface (corner indices `ti`, `ui`) meet other
/// than in the corners they share by index: a corner of one on a corner of the other with
/// another index is two points in one place, a pinch, however legal the coordinates alone look.
pub fn meet_improperly(t: &[P3; 3], ti: [u32; 3], u: &[P3; 3], ui: [u32; 3]) -> bool {
    let shared = ti.iter().filter(|v| ui.contains(v)).count();
    match tri_tri(t, u) {
        TriTri::Disjoint => false,
        TriTri::SharedVertex { .. } => shared != 1,
        TriTri::SharedEdge { .. } => shared != 2,
        TriTri::Improper => true,
    }
}

/// Drop coordinate `axis`, keeping the other two in cyclic order.
#[inline]
pub fn drop_axis(p: P3, axis: usize) -> P2 {
    match axis {
        0 => [p[1], p[2]],
        1 => [p[2], p[0]],
        _ => [p[0], p[1]],
    }
}

/// A coordinate axis along which the triangle projects to a non-degenerate 2D triangle, or
/// `None` for a degenerate triangle (collinear corners). The axis of the float normal's largest
/// component is preferred; the choice is verified exactly, so any returned axis gives a
/// projection that is an affine bijection of the triangle's plane onto the coordinate plane
/// (incidences and sidedness in the plane are preserved).
pub fn projection_axis(t: &[P3; 3]) -> Option<usize> {
    let u = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
    let v = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
    let n = [
        (u[1] * v[2] - u[2] * v[1]).abs(),
        (u[2] * v[0] - u[0] * v[2]).abs(),
        (u[0] * v[1] - u[1] * v[0]).abs(),
    ];
    let mut axes = [0usize, 1, 2];
    // Largest first; NaN (from infinite input) sorts anywhere, verification still applies.
    axes.sort_by(|&i, &j| n[j].partial_cmp(&n[i]).unwrap_or(std::cmp::Ordering::Equal));
    axes.into_iter().find(|&k| {
        orient2d(drop_axis(t[0], k), drop_axis(t[1], k), drop_axis(t[2], k)) != Sign::Zero
    })
}

/// Whether the triangle's corners are collinear (or repeated), decided exactly: all three
/// coordinate-plane projections have zero area.
pub fn is_degenerate(t: &[P3; 3]) -> bool {
    (0..3)
        .all(|k| orient2d(drop_axis(t[0], k), drop_axis(t[1], k), drop_axis(t[2], k)) == Sign::Zero)
}

// ---------------------------------------------------------------------------------------------
// 2D building blocks
// ---------------------------------------------------------------------------------------------

/// Whether `x` lies between `a` and `b` on both coordinates; for collinear points this is
/// exactly "x is on the closed segment ab".
#[inline]
fn between_2d(a: P2, b: P2, x: P2) -> bool {
    (0..2).all(|i| a[i].min(b[i]) <= x[i] && x[i] <= a[i].max(b[i]))
}

/// Whether the closed 2D segments `pq` and `rs` meet.
pub fn segments_meet_2d(p: P2, q: P2, r: P2, s: P2) -> bool {
    let o1 = orient2d(p, q, r);
    let o2 = orient2d(p, q, s);
    let o3 = orient2d(r, s, p);
    let o4 = orient2d(r, s, q);
    if o1 == Sign::Zero && o2 == Sign::Zero {
        // All four collinear (o3 = o4 = 0 then too): compare extents.
        return between_2d(p, q, r)
            || between_2d(p, q, s)
            || between_2d(r, s, p)
            || between_2d(r, s, q);
    }
    (o1 != o2 || o1 == Sign::Zero) && (o3 != o4 || o3 == Sign::Zero)
}

/// Whether `x` lies in the closed non-degenerate 2D triangle `t`.
pub fn point_in_triangle_2d(x: P2, t: &[P2; 3]) -> bool {
    let sigma = orient2d(t[0], t[1], t[2]);
    let bad = sigma.flip();
    orient2d(t[0], t[1], x) != bad
        && orient2d(t[1], t[2], x) != bad
        && orient2d(t[2], t[0], x) != bad
}

/// Whether the closed segment `pq` meets the closed non-degenerate 2D triangle `t`.
pub fn segment_meets_triangle_2d(p: P2, q: P2, t: &[P2; 3]) -> bool {
    point_in_triangle_2d(p, t)
        || point_in_triangle_2d(q, t)
        || (0..3).any(|k| segments_meet_2d(p, q, t[(k + 1) % 3], t[(k + 2) % 3]))
}

/// Whether two closed non-degenerate 2D triangles meet.
pub fn triangles_meet_2d(t: &[P2; 3], u: &[P2; 3]) -> bool {
    t.iter().any(|&p| point_in_triangle_2d(p, u))
        || u.iter().any(|&p| point_in_triangle_2d(p, t))
        || (0..3)
            .any(|i| (0..3).any(|j| segments_meet_2d(t[i], t[(i + 1) % 3], u[j], u[(j + 1) % 3])))
}

/// Whether `x` lies in the closed 2D wedge with apex `v` spanned by the rays towards `c` and
/// `d` (`v, c, d` not collinear, so the wedge is narrower than a half-plane).
fn in_wedge_2d(v: P2, c: P2, d: P2, x: P2) -> bool {
    let bad = orient2d(v, c, d).flip();
    orient2d(v, c, x) != bad && orient2d(v, x, d) != bad
}

// ---------------------------------------------------------------------------------------------
// Segment–triangle
// ---------------------------------------------------------------------------------------------

/// Classify how the closed segment `pq` meets the closed triangle `t` (see [`SegTri`]).
///
/// A segment that degenerates to a point (`p == q`) is handled: it is either disjoint, touching,
/// proper is impossible, or coplanar.
pub fn seg_tri(p: P3, q: P3, t: &[P3; 3]) -> SegTri {
    let [a, b, c] = *t;
    let sp = orient3d(a, b, c, p);
    let sq = orient3d(a, b, c, q);
    if sp == Sign::Zero && sq == Sign::Zero {
        let Some(k) = projection_axis(t) else {
            return SegTri::Disjoint;
        };
        let t2 = t.map(|x| drop_axis(x, k));
        return if segment_meets_triangle_2d(drop_axis(p, k), drop_axis(q, k), &t2) {
            SegTri::Coplanar
        } else {
            SegTri::Disjoint
        };
    }
    if sp == sq {
        return SegTri::Disjoint;
    }
    // The line pq crosses the plane at one point X. With d = q - p and n the triangle normal,
    // orient3d(p, q, b, c) = λ_a (d·n) where λ_a is X's barycentric coordinate, etc.; the sign
    // of d·n is that of vol(q) - vol(p).
    let dn_positive = sq == Sign::Positive || sp == Sign::Negative;
    let lam = [
        orient3d(p, q, b, c).times(dn_positive),
        orient3d(p, q, c, a).times(dn_positive),
        orient3d(p, q, a, b).times(dn_positive),
    ];
    if lam.contains(&Sign::Negative) {
        return SegTri::Disjoint;
    }
    let zeros = lam.iter().filter(|&&s| s == Sign::Zero).count();
    let tri = match zeros {
        0 => TriPart::Interior,
        1 => TriPart::Edge(lam.iter().position(|&s| s == Sign::Zero).unwrap() as u8),
        _ => TriPart::Vertex(lam.iter().position(|&s| s != Sign::Zero).unwrap_or(0) as u8),
    };
    let seg = if sp == Sign::Zero {
        SegPart::Endpoint(0)
    } else if sq == Sign::Zero {
        SegPart::Endpoint(1)
    } else {
        SegPart::Interior
    };
    if seg == SegPart::Interior && tri == TriPart::Interior {
        SegTri::Proper
    } else {
        SegTri::Touch { seg, tri }
    }
}

// ---------------------------------------------------------------------------------------------
// Triangle–triangle
// ---------------------------------------------------------------------------------------------

/// A projection axis valid for both triangles, which must be coplanar (one of them must be
/// non-degenerate).
fn coplanar_axis(t: &[P3; 3], u: &[P3; 3]) -> Option<usize> {
    projection_axis(t).or_else(|| projection_axis(u))
}

/// Whether two closed triangles meet at all (no shared-corner exemption).
pub fn triangles_meet(t: &[P3; 3], u: &[P3; 3]) -> bool {
    let su = t.map(|p| orient3d(u[0], u[1], u[2], p));
    if su[0] != Sign::Zero && su[0] == su[1] && su[1] == su[2] {
        return false;
    }
    let st = u.map(|p| orient3d(t[0], t[1], t[2], p));
    if st[0] != Sign::Zero && st[0] == st[1] && st[1] == st[2] {
        return false;
    }
    if su.iter().all(|&s| s == Sign::Zero) {
        let Some(k) = coplanar_axis(t, u) else {
            return true;
        };
        return triangles_meet_2d(&t.map(|p| drop_axis(p, k)), &u.map(|p| drop_axis(p, k)));
    }
    // Not coplanar: the intersection lies on the line where the planes meet, and each triangle
    // cuts that line in a segment whose ends are on its edges; two such segments overlap iff an
    // end of one lies in the other, i.e. iff some edge of one triangle meets the other triangle.
    (0..3).any(|k| seg_tri(t[k], t[(k + 1) % 3], u).meets())
        || (0..3).any(|k| seg_tri(u[k], u[(k + 1) % 3], t).meets())
}

/// Classify how two closed non-degenerate triangles meet (see [`TriTri`]). Corners are shared
/// when their coordinates are exactly equal.
///
/// With one shared corner `v` (`t = v a b`, `u = v c d`) the triangles meet elsewhere iff their
/// cones at `v` share a ray, iff the opposite edge `ab` meets the closed wedge of `u` at `v`
/// (every ray of `t`'s cone crosses `ab`). With a shared edge they meet elsewhere iff they are
/// coplanar and on the same side of it.
pub fn tri_tri(t: &[P3; 3], u: &[P3; 3]) -> TriTri {
    let mut shared: [(u8, u8); 3] = [(0, 0); 3];
    let mut m = 0;
    for (i, p) in t.iter().enumerate() {
        for (j, q) in u.iter().enumerate() {
            if p == q && m < 3 {
                shared[m] = (i as u8, j as u8);
                m += 1;
            }
        }
    }
    match m {
        0 => {
            if triangles_meet(t, u) {
                TriTri::Improper
            } else {
                TriTri::Disjoint
            }
        }
        1 => {
            let (i, j) = shared[0];
            let (i, j) = (i as usize, j as usize);
            let (v, a, b) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            let (c, d) = (u[(j + 1) % 3], u[(j + 2) % 3]);
            if shared_vertex_meets_elsewhere(v, a, b, c, d, t, u) {
                TriTri::Improper
            } else {
                TriTri::SharedVertex {
                    a: i as u8,
                    b: j as u8,
                }
            }
        }
        2 => {
            let (i0, j0) = shared[0];
            let (i1, j1) = shared[1];
            let ia = 3 - i0 as usize - i1 as usize;
            let jb = 3 - j0 as usize - j1 as usize;
            let (v, w) = (t[i0 as usize], t[i1 as usize]);
            let (a, b) = (t[ia], u[jb]);
            let legal = if orient3d(v, w, a, b) != Sign::Zero {
                true
            } else {
                // Coplanar: legal iff a and b are strictly on opposite sides of the line vw.
                match coplanar_axis(t, u) {
                    None => false,
                    Some(k) => {
                        let (v2, w2) = (drop_axis(v, k), drop_axis(w, k));
                        let sa = orient2d(v2, w2, drop_axis(a, k));
                        let sb = orient2d(v2, w2, drop_axis(b, k));
                        sa != Sign::Zero && sb == sa.flip()
                    }
                }
            };
            if legal {
                TriTri::SharedEdge {
                    a: [i0, i1],
                    b: [j0, j1],
                }
            } else {
                TriTri::Improper
            }
        }
        _ => TriTri::Improper,
    }
}

/// `t = v a b` and `u = v c d` share the corner `v`: do they meet anywhere else?
fn shared_vertex_meets_elsewhere(
    v: P3,
    a: P3,
    b: P3,
    c: P3,
    d: P3,
    t: &[P3; 3],
    u: &[P3; 3],
) -> bool {
    let sa = orient3d(v, c, d, a);
    let sb = orient3d(v, c, d, b);
    if sa == Sign::Zero && sb == Sign::Zero {
        // Coplanar: two wedges narrower than a half-plane share a ray iff a bounding ray of one
        // lies in the other.
        let Some(k) = coplanar_axis(t, u) else {
            return true;
        };
        let [v, a, b, c, d] = [v, a, b, c, d].map(|p| drop_axis(p, k));
        return in_wedge_2d(v, c, d, a)
            || in_wedge_2d(v, c, d, b)
            || in_wedge_2d(v, a, b, c)
            || in_wedge_2d(v, a, b, d);
    }
    if sa == sb {
        // ab strictly on one side of u's plane: only v is common.
        return false;
    }
    // ab meets u's plane at one point X (≠ v since t is non-degenerate); it is in u's wedge iff
    // its barycentric coordinates for c and d (w.r.t. v c d) are both ≥ 0.
    let dn_positive = sb == Sign::Positive || sa == Sign::Negative;
    let lc = orient3d(a, b, d, v).times(dn_positive);
    let ld = orient3d(a, b, v, c).times(dn_positive);
    lc != Sign::Negative && ld != Sign::Negative
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [P3; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    /// Two triangles touching at one place are a proper pair only if that place is one corner
    /// by index: two points with the same coordinates make a pinch.
    #[test]
    fn a_shared_place_is_a_shared_corner_only_by_index() {
        let u = [[0.0, 0.0, 0.0], [-1.0, 0.0, 1.0], [0.0, -1.0, 1.0]];
        assert!(matches!(tri_tri(&T, &u), TriTri::SharedVertex { .. }));
        assert!(!meet_improperly(&T, [0, 1, 2], &u, [0, 3, 4]));
        assert!(meet_improperly(&T, [0, 1, 2], &u, [5, 3, 4]));
        // An edge in one place: two shared corners by index, or it is a pinch along it.
        let w = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(!meet_improperly(&T, [0, 1, 2], &w, [1, 0, 6]));
        assert!(meet_improperly(&T, [0, 1, 2], &w, [1, 7, 6]));
        assert!(!meet_improperly(
            &T,
            [0, 1, 2],
            &[[5.0; 3], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]],
            [0, 1, 2]
        ));
    }

    #[test]
    fn segment_triangle_cases() {
        // Proper crossing.
        assert_eq!(
            seg_tri([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], &T),
            SegTri::Proper
        );
        // Misses beside the triangle.
        assert_eq!(
            seg_tri([0.8, 0.8, -1.0], [0.8, 0.8, 1.0], &T),
            SegTri::Disjoint
        );
        // Same side of the plane.
        assert_eq!(
            seg_tri([0.2, 0.2, 0.5], [0.2, 0.2, 1.0], &T),
            SegTri::Disjoint
        );
        // Through corner 1.
        assert_eq!(
            seg_tri([1.0, 0.0, -1.0], [1.0, 0.0, 1.0], &T),
            SegTri::Touch {
                seg: SegPart::Interior,
                tri: TriPart::Vertex(1)
            }
        );
        // Through the hypotenuse (edge opposite corner 0).
        assert_eq!(
            seg_tri([0.5, 0.5, -1.0], [0.5, 0.5, 1.0], &T),
            SegTri::Touch {
                seg: SegPart::Interior,
                tri: TriPart::Edge(0)
            }
        );
        // Endpoint on the interior.
        assert_eq!(
            seg_tri([0.2, 0.2, 0.0], [0.2, 0.2, 1.0], &T),
            SegTri::Touch {
                seg: SegPart::Endpoint(0),
                tri: TriPart::Interior
            }
        );
        // Coplanar overlap and coplanar miss.
        assert_eq!(
            seg_tri([-1.0, 0.2, 0.0], [2.0, 0.2, 0.0], &T),
            SegTri::Coplanar
        );
        assert_eq!(
            seg_tri([-1.0, -0.2, 0.0], [2.0, -0.2, 0.0], &T),
            SegTri::Disjoint
        );
        // Coplanar, touching a corner only.
        assert_eq!(
            seg_tri([1.0, 0.0, 0.0], [2.0, 0.0, 0.0], &T),
            SegTri::Coplanar
        );
    }

    #[test]
    fn triangle_triangle_cases() {
        // Interpenetrating.
        let u = [[0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Far apart.
        let u = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Disjoint);
        // Touching at a vertex that is not shared (u's corner on T's interior).
        let u = [[0.2, 0.2, 0.0], [0.3, 0.2, 1.0], [0.2, 0.3, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Sharing a corner only.
        let u = [[0.0, 0.0, 0.0], [-1.0, 0.0, 1.0], [0.0, -1.0, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::SharedVertex { a: 0, b: 0 });
        // Sharing a corner, an edge of u lying in T's plane and along T's edge: improper.
        let u = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Sharing a corner, an edge of u lying in T's plane but outside T: legal.
        let u = [[0.0, 0.0, 0.0], [-0.5, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::SharedVertex { a: 0, b: 0 });
        // Sharing a corner and piercing through T: improper.
        let u = [[0.0, 0.0, 0.0], [0.3, 0.3, 1.0], [0.3, 0.3, -1.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Sharing an edge, not coplanar.
        let u = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(
            tri_tri(&T, &u),
            TriTri::SharedEdge {
                a: [0, 1],
                b: [1, 0]
            }
        );
        // Sharing an edge, coplanar and on the other side: legal.
        let u = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, -1.0, 0.0]];
        assert!(matches!(tri_tri(&T, &u), TriTri::SharedEdge { .. }));
        // Sharing an edge, coplanar and folded onto T: improper.
        let u = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, 0.1, 0.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Coplanar overlap without shared corners.
        let u = [[0.1, 0.1, 0.0], [2.0, 0.1, 0.0], [0.1, 2.0, 0.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Coplanar, disjoint.
        let u = [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Disjoint);
        // Coplanar, sharing a corner only, wedges apart.
        let u = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
        assert!(matches!(tri_tri(&T, &u), TriTri::SharedVertex { .. }));
        // Coplanar, sharing a corner, wedges overlapping.
        let u = [[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 2.0, 0.0]];
        assert_eq!(tri_tri(&T, &u), TriTri::Improper);
        // Identical.
        assert_eq!(tri_tri(&T, &T), TriTri::Improper);
    }

    /// The kind of contact, without corner numbers.
    fn kind(r: TriTri) -> u8 {
        match r {
            TriTri::Disjoint => 0,
            TriTri::SharedVertex { .. } => 1,
            TriTri::SharedEdge { .. } => 2,
            TriTri::Improper => 3,
        }
    }

    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [1, 2, 0],
        [2, 0, 1],
        [0, 2, 1],
        [2, 1, 0],
        [1, 0, 2],
    ];

    fn lattice_tri(r: i32) -> impl Strategy<Value = [P3; 3]> {
        proptest::array::uniform3(proptest::array::uniform3((-r..=r).prop_map(|x| x as f64)))
            .prop_filter("non-degenerate", |t| !is_degenerate(t))
    }

    /// Pairs sharing 0, 1 or 2 corners, on a coarse lattice (lots of coplanar and touching
    /// configurations).
    fn lattice_pair() -> impl Strategy<Value = ([P3; 3], [P3; 3])> {
        (lattice_tri(2), lattice_tri(2), 0usize..3).prop_filter_map(
            "degenerate",
            |(t, mut u, k)| {
                u[..k].copy_from_slice(&t[..k]);
                (!is_degenerate(&u)).then_some((t, u))
            },
        )
    }

    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The classification does not depend on the order of the triangles, of their corners,
        /// on exact translations or on permuting and mirroring the axes (which changes the
        /// projections used in the coplanar cases).
        #[test]
        fn tri_tri_invariances((t, u) in lattice_pair(), axes in 0usize..6, flip in 0usize..8) {
            let k = kind(tri_tri(&t, &u));
            prop_assert_eq!(kind(tri_tri(&u, &t)), k);
            for p in PERMS {
                for q in PERMS {
                    let t2 = p.map(|i| t[i]);
                    let u2 = q.map(|i| u[i]);
                    prop_assert_eq!(kind(tri_tri(&t2, &u2)), k);
                }
            }
            let a = PERMS[axes];
            let map = |x: P3| {
                [0, 1, 2].map(|i| {
                    let v = x[a[i]] + [1e6 + 0.5, -3.25, 2f64.powi(30)][i];
                    if flip >> i & 1 == 1 { -v } else { v }
                })
            };
            prop_assert_eq!(kind(tri_tri(&t.map(map), &u.map(map))), k);
            // Without shared corners, "meets" is exactly "some edge meets the other triangle".
            if k == 0 || (k == 3 && !t.iter().any(|p| u.contains(p))) {
                let edges = (0..3).any(|i| seg_tri(t[i], t[(i + 1) % 3], &u).meets())
                    || (0..3).any(|i| seg_tri(u[i], u[(i + 1) % 3], &t).meets());
                prop_assert_eq!(edges, k == 3);
            }
        }

        /// Segment–triangle: symmetric in the segment's ends, invariant under corner order.
        #[test]
        fn seg_tri_invariances(
            t in lattice_tri(2),
            p in proptest::array::uniform3((-2i32..=2).prop_map(|x| x as f64)),
            q in proptest::array::uniform3((-2i32..=2).prop_map(|x| x as f64)),
        ) {
            let r = seg_tri(p, q, &t);
            let swapped = match seg_tri(q, p, &t) {
                SegTri::Touch { seg: SegPart::Endpoint(e), tri } => {
                    SegTri::Touch { seg: SegPart::Endpoint(1 - e), tri }
                }
                x => x,
            };
            if p != q {
                prop_assert_eq!(swapped, r);
            }
            for perm in PERMS {
                let t2 = perm.map(|i| t[i]);
                let r2 = seg_tri(p, q, &t2);
                // Same kind; triangle parts renumbered.
                let renum = |x: SegTri| match x {
                    SegTri::Touch { seg, tri: TriPart::Vertex(k) } => SegTri::Touch {
                        seg,
                        tri: TriPart::Vertex(perm[k as usize] as u8),
                    },
                    SegTri::Touch { seg, tri: TriPart::Edge(k) } => SegTri::Touch {
                        seg,
                        tri: TriPart::Edge(perm[k as usize] as u8),
                    },
                    x => x,
                };
                prop_assert_eq!(renum(r2), r);
            }
        }
    }

    /// Independent oracle for lattice triangles: closed convex sets are disjoint iff some axis
    /// among the face normals, edge × edge and normal × edge separates their projections
    /// strictly; exact in integers.
    fn sat_meet(t: &[P3; 3], u: &[P3; 3]) -> bool {
        let ti = t.map(|p| p.map(|x| x as i128));
        let ui = u.map(|p| p.map(|x| x as i128));
        let sub = |a: [i128; 3], b: [i128; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [i128; 3], b: [i128; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [i128; 3], b: [i128; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let edges = |x: &[[i128; 3]; 3]| [0, 1, 2].map(|i| sub(x[(i + 1) % 3], x[i]));
        let (et, eu) = (edges(&ti), edges(&ui));
        let (nt, nu) = (cross(et[0], et[1]), cross(eu[0], eu[1]));
        let mut axes = vec![nt, nu];
        for a in et {
            for b in eu {
                axes.push(cross(a, b));
            }
            axes.push(cross(nt, a));
        }
        for b in eu {
            axes.push(cross(nu, b));
        }
        !axes.iter().any(|&ax| {
            let pt = ti.map(|p| dot(p, ax));
            let pu = ui.map(|p| dot(p, ax));
            let (tmin, tmax) = (*pt.iter().min().unwrap(), *pt.iter().max().unwrap());
            let (umin, umax) = (*pu.iter().min().unwrap(), *pu.iter().max().unwrap());
            tmax < umin || umax < tmin
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 5000,
            max_global_rejects: 100_000,
            ..ProptestConfig::default()
        })]

        #[test]
        fn triangles_meet_matches_separating_axes(t in lattice_tri(2), u in lattice_tri(2)) {
            prop_assert_eq!(triangles_meet(&t, &u), sat_meet(&t, &u));
            // With no shared corner, tri_tri reports exactly whether they meet.
            if !t.iter().any(|p| u.contains(p)) {
                prop_assert_eq!(tri_tri(&t, &u) == TriTri::Improper, sat_meet(&t, &u));
            }
        }

        /// Coplanar pairs (all in z = 0, or in the tilted plane z = x + y).
        #[test]
        fn coplanar_meet_matches_separating_axes(
            t in proptest::array::uniform3(proptest::array::uniform2(-3i32..=3)),
            u in proptest::array::uniform3(proptest::array::uniform2(-3i32..=3)),
            tilt in any::<bool>(),
        ) {
            let lift = |p: [i32; 2]| {
                let (x, y) = (p[0] as f64, p[1] as f64);
                [x, y, if tilt { x + y } else { 0.0 }]
            };
            let (t, u) = (t.map(lift), u.map(lift));
            prop_assume!(!is_degenerate(&t) && !is_degenerate(&u));
            prop_assert_eq!(triangles_meet(&t, &u), sat_meet(&t, &u));
        }
    }

    #[test]
    fn degeneracy_and_projection() {
        assert!(is_degenerate(&[[0.0; 3], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]));
        assert!(is_degenerate(&[[0.0; 3], [0.0; 3], [2.0, 2.0, 2.0]]));
        assert!(!is_degenerate(&T));
        // A triangle in a vertical plane cannot use the z projection.
        let v = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let k = projection_axis(&v).unwrap();
        assert_ne!(k, 2);
        assert_eq!(projection_axis(&[[0.0; 3], [1.0; 3], [3.0; 3]]), None);
    }
}
