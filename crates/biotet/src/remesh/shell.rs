//! `--allow-shell-changes`: sliver removal across a remeshed zone's shell.
//!
//! The refill keeps its shell triangle for triangle, so a poor tet standing on the shell can only
//! be improved from the new side. With the user's leave, the kept tets sharing a corner with the
//! new ones, and of the same region, are offered to sliver removal too ([`crate::lastresort::improve()`]): the new tets
//! and that ring form one mesh whose outer faces (towards the rest of the kept mesh), boundary
//! and interfaces sliver removal keeps, as it keeps any mesh's; no point is added, moved or
//! dropped. Every kept tet outside the ring stays bit for bit; the ring's tets that were
//! replaced are reported by their input index.

use crate::lastresort::{ImproveOptions, ImproveReport, improve};
use crate::mesh::tet::TetMesh;
use rustc_hash::FxHashSet;
use serde::Serialize;
use std::time::Instant;

use super::RemeshReport;

/// What [`across_shell`] changed.
#[derive(Debug, Clone, Serialize)]
pub struct ShellChanges {
    /// Kept tets sharing a corner with a new one of their region, offered to sliver removal.
    pub kept_offered: usize,
    /// Input indices of the kept tets it replaced (sorted).
    pub kept_replaced: Vec<u32>,
    /// Tets of the new zone and the offered ring, before and after.
    pub tets_before: usize,
    /// See `tets_before`.
    pub tets_after: usize,
    /// Sliver removal's report on them.
    pub improve: ImproveReport,
    /// Seconds in all.
    pub seconds: f64,
}

/// Run sliver removal over the new tets of `mesh` (those from `report.tets_kept` on, as
/// [`super::remesh`] and [`super::insert`] leave them) and the kept tets of their regions
/// sharing a corner with them. The kept tets left untouched come first in the output, `report` is updated, and the
/// changes are recorded in it.
pub fn across_shell(mesh: &TetMesh, report: &mut RemeshReport, opts: &ImproveOptions) -> TetMesh {
    let start = Instant::now();
    let kept = report.tets_kept;
    // The labels of the new tets at each point: a kept tet of another label is across an
    // interface that sliver removal keeps, so only the new tets' own labels are offered.
    let mut on_new: Vec<Vec<u32>> = vec![Vec::new(); mesh.points.len()];
    for (t, &l) in mesh.tets[kept..].iter().zip(&mesh.labels[kept..]) {
        for &v in t {
            let at = &mut on_new[v as usize];
            if !at.contains(&l) {
                at.push(l);
            }
        }
    }
    let ring: Vec<usize> = (0..kept)
        .filter(|&t| {
            let l = mesh.labels[t];
            mesh.tets[t]
                .iter()
                .any(|&v| on_new[v as usize].contains(&l))
        })
        .collect();
    let mut in_ring = vec![false; kept];
    for &t in &ring {
        in_ring[t] = true;
    }
    let zone: Vec<usize> = ring.iter().copied().chain(kept..mesh.tets.len()).collect();
    let mut sub = TetMesh::new(
        mesh.points.clone(),
        zone.iter().map(|&t| mesh.tets[t]).collect(),
        zone.iter().map(|&t| mesh.labels[t]).collect(),
    );
    sub.rebuild_neighbors();
    let improve_report = improve(&mut sub, opts);
    // A ring tet survives when its corners (and label) are still a tet of the zone.
    let key = |t: &[u32; 4], l: u32| {
        let mut k = *t;
        k.sort_unstable();
        (k, l)
    };
    let after: FxHashSet<([u32; 4], u32)> = sub
        .tets
        .iter()
        .zip(&sub.labels)
        .map(|(t, &l)| key(t, l))
        .collect();
    let survived: FxHashSet<([u32; 4], u32)> = ring
        .iter()
        .map(|&t| key(&mesh.tets[t], mesh.labels[t]))
        .filter(|k| after.contains(k))
        .collect();
    let mut kept_replaced: Vec<u32> = ring
        .iter()
        .filter(|&&t| !survived.contains(&key(&mesh.tets[t], mesh.labels[t])))
        .map(|&t| report.kept_input[t])
        .collect();
    kept_replaced.sort_unstable();
    // Untouched kept tets first (the rest of the kept mesh in its order, then the ring's
    // survivors), then the zone's other tets in the order sliver removal left them.
    let mut tets = Vec::with_capacity(kept + sub.tets.len());
    let mut labels = Vec::with_capacity(tets.capacity());
    let mut kept_input = Vec::with_capacity(kept);
    let untouched = (0..kept).filter(|&t| !in_ring[t]).chain(
        ring.iter()
            .copied()
            .filter(|&t| survived.contains(&key(&mesh.tets[t], mesh.labels[t]))),
    );
    for t in untouched {
        tets.push(mesh.tets[t]);
        labels.push(mesh.labels[t]);
        kept_input.push(report.kept_input[t]);
    }
    let new_kept = tets.len();
    for (t, &l) in sub.tets.iter().zip(&sub.labels) {
        // A surviving ring tet is listed once, among the kept (no new tet has its corners).
        if !survived.contains(&key(t, l)) {
            tets.push(*t);
            labels.push(l);
        }
    }
    let mut out = TetMesh::new(sub.points, tets, labels);
    out.rebuild_neighbors();
    report.tets_kept = new_kept;
    report.kept_input = kept_input;
    report.tets_after = out.tets.len();
    report.shell_changes = Some(ShellChanges {
        kept_offered: ring.len(),
        kept_replaced,
        tets_before: zone.len(),
        tets_after: sub.tets.len(),
        improve: improve_report,
        seconds: start.elapsed().as_secs_f64(),
    });
    report.seconds_total += start.elapsed().as_secs_f64();
    out
}
