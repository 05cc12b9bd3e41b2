//! Which voxel values become which regions: `--merge`, `--outside`, `--labels`, and small
//! islands (6-connected components below `--min-component-voxels`) merged into their
//! surroundings.
//!
//! Order of operations: merges first (on the file's values), then the outside value becomes 0,
//! then labels not kept become 0, then islands. Every remaining non-zero value is a region whose
//! mesh label is that value (FreeSurfer's 17 stays 17).

use rustc_hash::FxHashMap;

use super::LabelImage;

/// How voxel values become regions.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LabelOptions {
    /// Keep only these labels (after merging); the others become outside. `None` keeps all.
    pub keep: Option<Vec<u32>>,
    /// `(sources, target)`: every source value becomes `target`.
    pub merge: Vec<(Vec<u32>, u32)>,
    /// The value of the outside (default 0).
    pub outside: u32,
    /// 6-connected components with fewer voxels are merged into the label most of their
    /// neighbours have (0: keep all). The outside component touching the image border is never
    /// merged.
    pub min_component_voxels: usize,
}

/// An island merged into its surroundings.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct MergedIsland {
    /// Its label before.
    pub label: u32,
    /// Its label after.
    pub into: u32,
    /// Its voxels.
    pub voxels: usize,
}

/// What [`apply`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct LabelReport {
    /// Voxels per region label after everything (0 excluded), sorted by label.
    pub regions: Vec<(u32, usize)>,
    /// Voxels set to the outside because their label was not kept.
    pub dropped_voxels: usize,
    /// Islands merged (`--min-component-voxels`).
    pub islands: Vec<MergedIsland>,
    /// Connected components per region label after merging islands, sorted by label.
    pub components: Vec<(u32, usize)>,
}

/// Why labels cannot be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LabelError {
    /// Voxels hold 0 while another value is the outside: 0 is the outside's mesh label.
    #[error(
        "{0} voxels have value 0 but the outside is {1}: 0 is the mesh label of the outside; \
         merge 0 into another label (--merge 0=N) or name it the outside"
    )]
    ZeroNotOutside(usize, u32),
    /// A label listed twice as a merge source.
    #[error("label {0} is merged twice")]
    MergedTwice(u32),
    /// No region left.
    #[error("no region: every voxel is outside (value {0})")]
    Empty(u32),
    /// `--labels` kept none of the image's labels.
    #[error("--labels {asked}: no voxel has one of these labels (the image's: {present})")]
    NothingKept {
        /// The labels asked for.
        asked: String,
        /// The image's region labels (after merging).
        present: String,
    },
    /// `--min-component-voxels` merged every region away (each of its components was smaller:
    /// a checkerboard of single voxels).
    #[error(
        "--min-component-voxels {0}: every region's components are smaller than that, so none \
         is left; give a smaller number"
    )]
    IslandsTookAll(usize),
}

/// Apply the options to an image in place.
pub fn apply(img: &mut LabelImage, opts: &LabelOptions) -> Result<LabelReport, LabelError> {
    let mut map: FxHashMap<u32, u32> = FxHashMap::default();
    for (sources, target) in &opts.merge {
        for &s in sources {
            if map.insert(s, *target).is_some() {
                return Err(LabelError::MergedTwice(s));
            }
        }
    }
    let keep: Option<rustc_hash::FxHashSet<u32>> =
        opts.keep.as_ref().map(|k| k.iter().copied().collect());
    let mut zeros = 0usize;
    let mut dropped = 0usize;
    // The labels `keep` dropped, for its message should it keep none (a set insert only where
    // the dropped value changes along the voxels).
    let mut dropped_labels: rustc_hash::FxHashSet<u32> = rustc_hash::FxHashSet::default();
    let mut last_dropped = None;
    let mut kept_any = false;
    for l in img.labels.iter_mut() {
        let mut v = map.get(l).copied().unwrap_or(*l);
        if v == opts.outside {
            v = 0;
        } else if v == 0 {
            zeros += 1;
        } else if let Some(k) = &keep {
            if k.contains(&v) {
                kept_any = true;
            } else {
                if last_dropped != Some(v) {
                    dropped_labels.insert(v);
                    last_dropped = Some(v);
                }
                v = 0;
                dropped += 1;
            }
        }
        *l = v;
    }
    if zeros > 0 {
        return Err(LabelError::ZeroNotOutside(zeros, opts.outside));
    }
    if let Some(k) = &opts.keep
        && !kept_any
        && dropped > 0
    {
        let mut present: Vec<u32> = dropped_labels.into_iter().collect();
        present.sort_unstable();
        return Err(LabelError::NothingKept {
            asked: crate::text::labels(k.iter().copied()),
            present: crate::text::labels(present),
        });
    }
    let any_region = img.labels.iter().any(|&l| l != 0);
    let islands = if opts.min_component_voxels > 0 {
        merge_islands(img, opts.min_component_voxels)
    } else {
        Vec::new()
    };
    let regions: Vec<(u32, usize)> = img.counts().into_iter().filter(|c| c.0 != 0).collect();
    if regions.is_empty() {
        return Err(if any_region {
            LabelError::IslandsTookAll(opts.min_component_voxels)
        } else {
            LabelError::Empty(opts.outside)
        });
    }
    let comps = Components::of(img);
    let mut per: FxHashMap<u32, usize> = FxHashMap::default();
    for c in &comps.list {
        if c.label != 0 {
            *per.entry(c.label).or_default() += 1;
        }
    }
    let mut components: Vec<(u32, usize)> = per.into_iter().collect();
    components.sort_unstable();
    Ok(LabelReport {
        regions,
        dropped_voxels: dropped,
        islands,
        components,
    })
}

/// One 6-connected component.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Component {
    /// Its label.
    pub label: u32,
    /// Its voxels.
    pub voxels: usize,
    /// Whether it touches the image border.
    pub border: bool,
    /// One of its voxels (linear index).
    pub seed: usize,
}

/// The 6-connected components of every label (the outside included).
#[derive(Debug, Clone)]
pub struct Components {
    /// Component of each voxel.
    pub of_voxel: Vec<u32>,
    /// The components, in order of their first voxel.
    pub list: Vec<Component>,
}

/// The up-to-six face neighbours of voxel `v` (linear index).
#[inline]
pub(crate) fn face_neighbours(dims: [usize; 3], v: usize, mut f: impl FnMut(usize)) {
    let (nx, ny) = (dims[0], dims[1]);
    let i = v % nx;
    let j = (v / nx) % ny;
    let k = v / (nx * ny);
    if i > 0 {
        f(v - 1);
    }
    if i + 1 < nx {
        f(v + 1);
    }
    if j > 0 {
        f(v - nx);
    }
    if j + 1 < ny {
        f(v + nx);
    }
    if k > 0 {
        f(v - nx * ny);
    }
    if k + 1 < dims[2] {
        f(v + nx * ny);
    }
}

/// Whether voxel `v` (linear index) lies on the image's border.
pub(crate) fn on_border(dims: [usize; 3], v: usize) -> bool {
    let i = v % dims[0];
    let j = (v / dims[0]) % dims[1];
    let k = v / (dims[0] * dims[1]);
    i == 0 || j == 0 || k == 0 || i + 1 == dims[0] || j + 1 == dims[1] || k + 1 == dims[2]
}

impl Components {
    /// Label 6-connected components by breadth-first search.
    pub fn of(img: &LabelImage) -> Components {
        const NONE: u32 = u32::MAX;
        let mut of_voxel = vec![NONE; img.len()];
        let mut list = Vec::new();
        let mut queue = Vec::new();
        for s in 0..img.len() {
            if of_voxel[s] != NONE {
                continue;
            }
            let id = list.len() as u32;
            let label = img.labels[s];
            let mut c = Component {
                label,
                voxels: 0,
                border: false,
                seed: s,
            };
            of_voxel[s] = id;
            queue.clear();
            queue.push(s);
            while let Some(v) = queue.pop() {
                c.voxels += 1;
                c.border |= on_border(img.dims, v);
                face_neighbours(img.dims, v, |w| {
                    if of_voxel[w] == NONE && img.labels[w] == label {
                        of_voxel[w] = id;
                        queue.push(w);
                    }
                });
            }
            list.push(c);
        }
        Components { of_voxel, list }
    }
}

/// Merge components smaller than `min` into the label most of their face neighbours have
/// (ties: the smaller label). The outside component(s) touching the border stay.
fn merge_islands(img: &mut LabelImage, min: usize) -> Vec<MergedIsland> {
    let comps = Components::of(img);
    let mut merged = Vec::new();
    let mut members: Vec<usize> = Vec::new();
    for (id, c) in comps.list.iter().enumerate() {
        if c.voxels >= min || (c.label == 0 && c.border) {
            continue;
        }
        // Gather its voxels and count its neighbours' labels.
        members.clear();
        let mut count: FxHashMap<u32, usize> = FxHashMap::default();
        let mut stack = vec![c.seed];
        let mut seen = rustc_hash::FxHashSet::default();
        seen.insert(c.seed);
        while let Some(v) = stack.pop() {
            members.push(v);
            face_neighbours(img.dims, v, |w| {
                if comps.of_voxel[w] == id as u32 {
                    if seen.insert(w) {
                        stack.push(w);
                    }
                } else {
                    *count.entry(img.labels[w]).or_default() += 1;
                }
            });
        }
        let Some((&into, _)) = count
            .iter()
            .filter(|(l, _)| **l != c.label)
            .max_by_key(|(l, n)| (**n, std::cmp::Reverse(**l)))
        else {
            continue; // the whole image is this component
        };
        for &v in &members {
            img.labels[v] = into;
        }
        merged.push(MergedIsland {
            label: c.label,
            into,
            voxels: c.voxels,
        });
    }
    merged
}

/// Image labels renumbered 1, 2, … for the mesher, whose template holds region labels up to
/// [`crate::template::voxels::MAX_REGION`]; the image's own values are put back on the tets after
/// meshing ([`Compaction::restore_tets`]). At most that many regions can be meshed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Compaction {
    /// `original[c]` is the image label of compact label `c` (`original[0] = 0`).
    pub original: Vec<u32>,
}

impl Compaction {
    /// Renumber a surface's labels in increasing order of value (0 stays 0).
    pub fn of_surface(s: &mut crate::SurfaceMesh) -> Compaction {
        let original = std::iter::once(0).chain(s.regions()).collect();
        let c = Compaction { original };
        for side in s.sides.iter_mut() {
            for l in side.iter_mut() {
                *l = c.compact(*l).expect("every label is listed");
            }
        }
        c
    }

    /// Whether `s` uses a label the template cannot hold, so it must be renumbered to mesh
    /// (an image's surface always is; a surface's labels only when they are that large, as
    /// FreeSurfer's 2035 and the labels of an extracted segmentation can be).
    pub fn needed(s: &crate::SurfaceMesh) -> bool {
        s.regions()
            .last()
            .is_some_and(|&l| l > crate::template::voxels::MAX_REGION)
    }

    /// The compact label of an image label.
    pub fn compact(&self, label: u32) -> Option<u32> {
        self.original.binary_search(&label).ok().map(|i| i as u32)
    }

    /// Whether the renumbering changes anything.
    pub fn is_identity(&self) -> bool {
        self.original
            .iter()
            .enumerate()
            .all(|(i, &l)| i as u32 == l)
    }

    /// Put the image's labels back on a surface.
    pub fn restore_surface(&self, s: &mut crate::SurfaceMesh) {
        for side in s.sides.iter_mut() {
            for l in side.iter_mut() {
                *l = self.original[*l as usize];
            }
        }
    }

    /// Put the image's labels back on the surface stage's report (its sheets and regions).
    pub fn restore_report(&self, r: &mut crate::surface::SurfaceReport) {
        let back = |l: &mut u32| *l = self.original.get(*l as usize).copied().unwrap_or(*l);
        for s in r.sheets.iter_mut() {
            s.sides.iter_mut().for_each(back);
        }
        for v in r.regions.iter_mut() {
            back(&mut v.label);
        }
    }

    /// Put the image's labels back on a tet mesh.
    pub fn restore_tets(&self, m: &mut crate::TetMesh) {
        for l in m.labels.iter_mut() {
            if let Some(&o) = self.original.get(*l as usize) {
                *l = o;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(dims: [usize; 3], labels: Vec<u32>) -> LabelImage {
        LabelImage::axis_aligned(dims, [1.0; 3], [0.0; 3], labels).unwrap()
    }

    #[test]
    fn merge_keep_outside() {
        let mut m = img([5, 1, 1], vec![9, 2, 41, 3, 9]);
        let r = apply(
            &mut m,
            &LabelOptions {
                keep: Some(vec![1]),
                merge: vec![(vec![2, 41], 1)],
                outside: 9,
                min_component_voxels: 0,
            },
        )
        .unwrap();
        assert_eq!(m.labels, vec![0, 1, 1, 0, 0]);
        assert_eq!(r.dropped_voxels, 1);
        assert_eq!(r.regions, vec![(1, 2)]);
        let mut z = img([2, 1, 1], vec![0, 5]);
        let o = LabelOptions {
            outside: 5,
            ..Default::default()
        };
        assert_eq!(apply(&mut z, &o), Err(LabelError::ZeroNotOutside(1, 5)));
    }

    /// Until session 33 both said "no region: every voxel is outside (value 0)", which named
    /// neither the option nor the cause.
    #[test]
    fn an_empty_result_names_the_option_that_emptied_it() {
        let mut m = img([4, 1, 1], vec![0, 1, 2, 3]);
        let keep = LabelOptions {
            keep: Some(vec![42]),
            ..Default::default()
        };
        assert_eq!(
            apply(&mut m, &keep).unwrap_err().to_string(),
            "--labels 42: no voxel has one of these labels (the image's: 1, 2, 3)"
        );
        // A checkerboard of single voxels inside the outside: every component is an island.
        let mut c = img(
            [4, 4, 1],
            vec![0, 0, 0, 0, 0, 1, 2, 0, 0, 2, 1, 0, 0, 0, 0, 0],
        );
        let islands = LabelOptions {
            min_component_voxels: 2,
            ..Default::default()
        };
        assert_eq!(apply(&mut c, &islands), Err(LabelError::IslandsTookAll(2)));
        let mut e = img([2, 1, 1], vec![0, 0]);
        assert_eq!(
            apply(&mut e, &LabelOptions::default()),
            Err(LabelError::Empty(0))
        );
    }

    #[test]
    fn compaction_round_trips() {
        let mut s = crate::SurfaceMesh {
            points: vec![],
            triangles: vec![],
            sides: vec![[41, 0], [17, 41], [2035, 17]],
        };
        let c = Compaction::of_surface(&mut s);
        assert_eq!(s.sides, vec![[2, 0], [1, 2], [3, 1]]);
        assert_eq!(c.compact(2035), Some(3));
        assert!(!c.is_identity());
        c.restore_surface(&mut s);
        assert_eq!(s.sides, vec![[41, 0], [17, 41], [2035, 17]]);
    }

    #[test]
    fn islands_merge_into_surroundings() {
        // A 5³ block of 1 with one voxel of 2 in the middle and a 0 hole of one voxel.
        let mut l = vec![1u32; 125];
        l[62] = 2;
        l[31] = 0;
        let mut m = img([5, 5, 5], l);
        let r = apply(
            &mut m,
            &LabelOptions {
                min_component_voxels: 2,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.islands.len(), 2);
        assert!(m.labels.iter().all(|&x| x == 1));
        assert_eq!(r.components, vec![(1, 1)]);
    }
}
