//! Mesh validity for host-sim: [`analyse`] (topology counts of one mesh) and [`compare`]
//! (whether a simplification is a valid one of its input), on [`MeshData`].
//!
//! The checker itself is the `meshcheck` crate (`meshcheck`), shared with the
//! library's tests and the fuzz targets; its documentation has the definitions, which match
//! `tests/fixtures/SOURCES.md`. This module only adapts it to host-sim's mesh type.

use crate::io::MeshData;

pub use meshcheck::{Defect, Topology, Verdict as Validity, FOLD_DOT};

/// Counts everything in [`Topology`].
pub fn analyse(mesh: &MeshData) -> Topology {
    meshcheck::analyse(&mesh.positions, &mesh.triangles).topology
}

/// Whether `output` is a valid simplification of `input` (same vertex numbering; the output's
/// positions of the vertices it uses must be the input's).
pub fn compare(input: &MeshData, output: &MeshData) -> Validity {
    compare_with(input, output, false)
}

/// [`compare`]; with `allow_moved`, kept vertices may have moved (optimal placement).
pub fn compare_with(input: &MeshData, output: &MeshData, allow_moved: bool) -> Validity {
    compare_opts(input, output, allow_moved, false)
}

/// [`compare_with`]; with `welded`, seams were welded (`tinydecimate::seam`): both meshes are
/// compared welded by position, and the kept positions' wedges must survive.
pub fn compare_opts(
    input: &MeshData,
    output: &MeshData,
    allow_moved: bool,
    welded: bool,
) -> Validity {
    compare_parts(input, output, allow_moved, welded, false)
}

/// [`compare_opts`]; with `parts`, an input component the output does not touch was removed
/// whole on purpose (`Simplifier::with_parts`): counted, and the rest compared
/// (`meshcheck::Options::parts`).
pub fn compare_parts(
    input: &MeshData,
    output: &MeshData,
    allow_moved: bool,
    welded: bool,
    parts: bool,
) -> Validity {
    meshcheck::check_with(
        meshcheck::MeshRef {
            positions: &input.positions,
            triangles: &input.triangles,
        },
        meshcheck::MeshRef {
            positions: &output.positions,
            triangles: &output.triangles,
        },
        &meshcheck::Options {
            view: None,
            allow_moved,
            welded,
            parts,
        },
    )
}

/// What a simplification promises, as `simplify`'s options say: the rules its own verdict
/// and `check`'s both apply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Promise {
    /// Optimal placement: kept vertices may have moved (`--placement optimal`).
    pub moved: bool,
    /// Seams welded (`--seams weld`, simplify's default): both meshes compared welded by
    /// position, so a seam pulled apart is a crack and twins are one vertex.
    pub welded: bool,
    /// Parts may vanish whole (`--parts prune`, simplify's default).
    pub parts: bool,
}

impl Default for Promise {
    /// `simplify`'s defaults: subset placement, seams welded, parts pruned.
    fn default() -> Self {
        Promise {
            moved: false,
            welded: true,
            parts: true,
        }
    }
}

/// The one verdict on a simplified mesh as read from its file, shared by `check` and
/// `simplify` (which checks what it wrote, read back): `output` in `input`'s numbering
/// (matched by position unless `promise.moved`, see [`renumbered`]), the note on how, and
/// the validity under `promise`. With `moved` (optimal placement) kept vertices may have
/// moved and vertices are matched by index: an output with another vertex count is refused,
/// as nothing else says which input vertex an output vertex was.
pub fn verdict(
    input: &MeshData,
    output: &MeshData,
    promise: Promise,
) -> anyhow::Result<(MeshData, Option<String>, Validity)> {
    let Promise {
        moved,
        welded,
        parts,
    } = promise;
    if moved {
        if output.positions.len() != input.positions.len() {
            anyhow::bail!(
                "with --placement optimal the simplified mesh's vertices are matched to the \
                 input's by index, so it must keep the input's numbering: it has {} vertices, \
                 the input {} (`simplify --placement optimal` writes OBJ and PLY files that way)",
                output.positions.len(),
                input.positions.len()
            );
        }
        let v = compare_parts(input, output, true, welded, parts);
        return Ok((output.clone(), None, v));
    }
    let (b, mut note) = renumbered(input, output, welded);
    let v = compare_parts(input, &b, false, welded, parts);
    if v.new_vertices > 0 && note.is_none() {
        note = Some(format!(
            "{} vertices are not at their input position: a result of optimal placement \
             (written in the input's numbering) is checked with `--placement optimal`",
            v.new_vertices
        ));
    }
    Ok((b, note, v))
}

/// Whether `output` uses `input`'s numbering: every vertex an output triangle uses is an
/// input vertex at the same position.
pub fn same_numbering(input: &MeshData, output: &MeshData) -> bool {
    output.triangles.iter().flatten().all(|&i| {
        let i = i as usize;
        i < input.positions.len() && output.positions.get(i) == input.positions.get(i)
    })
}

/// `output` in `input`'s numbering: itself if it already is, else matched back by position
/// ([`crate::io::renumber_onto`]) when it is an order-keeping subset of the input's vertices.
/// The note says what was done, if anything, and (`welded`: the check welds by position) what
/// a match among vertices at one position can change.
pub fn renumbered(input: &MeshData, output: &MeshData, welded: bool) -> (MeshData, Option<String>) {
    if same_numbering(input, output) {
        return (output.clone(), None);
    }
    match crate::io::renumber_onto(input, output) {
        Some((m, twins)) => {
            let mut note = format!(
                "the simplified mesh has its own vertex numbering ({} vertices): matched back \
                 onto the original's by position",
                output.positions.len()
            );
            if twins > 0 && welded {
                note += &format!(
                    "; {twins} of them share their position with another original vertex and \
                     were matched in order: the check welds by position, so only the count of \
                     wedges gone with faces depends on it (--keep-numbering writes an exact one)"
                );
            } else if twins > 0 {
                note += &format!(
                    "; {twins} of them share their position with another original vertex and \
                     were matched in order (write with --keep-numbering for an exact check)"
                );
            }
            (m, Some(note))
        }
        None => (output.clone(), None),
    }
}

/// The parts `simplify` simplifies and judges one at a time, each in its own numbering: a glTF
/// file's triangle primitives, or an OBJ file's material groups when its faces carry texture
/// coordinates or normals. `None` for anything `simplify` takes as one mesh (and for standard
/// input).
pub fn parts_of(path: &std::path::Path) -> anyhow::Result<Option<Vec<(String, MeshData)>>> {
    if crate::io::is_std(path) {
        return Ok(None);
    }
    if crate::io::gltf::is_gltf_path(path) {
        let file = crate::io::gltf::load(path)?;
        return Ok(Some(
            file.primitives
                .iter()
                .map(|p| {
                    let mesh = MeshData {
                        positions: p.positions.clone(),
                        triangles: p.triangles.clone(),
                    };
                    (crate::io::gltf::label(p), mesh)
                })
                .collect(),
        ));
    }
    if crate::io::format_of(path).ok() != Some(crate::io::Format::Obj) {
        return Ok(None);
    }
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    if !crate::io::objattr::has_attributes(&bytes) {
        return Ok(None);
    }
    let file = crate::io::objattr::parse(&bytes)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(Some(
        (0..file.groups.len())
            .map(|g| {
                let name = file.groups[g].material.as_deref().unwrap_or("(none)");
                (format!("material {name}"), file.mesh(g))
            })
            .collect(),
    ))
}

/// One part's verdict, as [`verdict`] gives it.
pub struct PartVerdict {
    /// The part's label (`material NAME`, or a glTF primitive's).
    pub label: String,
    /// How the output part was matched back onto the input part, if it was.
    pub note: Option<String>,
    /// The part's validity.
    pub validity: Validity,
}

/// [`verdict`] per part, as `simplify` judges a file with several parts ([`parts_of`]):
/// `None` unless both files have the same number (more than one) of parts.
pub fn part_verdicts(
    input: &std::path::Path,
    output: &std::path::Path,
    promise: Promise,
) -> anyhow::Result<Option<Vec<PartVerdict>>> {
    let (Some(a), Some(b)) = (parts_of(input)?, parts_of(output)?) else {
        return Ok(None);
    };
    if a.len() < 2 || a.len() != b.len() {
        return Ok(None);
    }
    let mut out = Vec::new();
    for ((label, pa), (_, pb)) in a.iter().zip(&b) {
        let (_, note, validity) = verdict(pa, pb, promise)?;
        out.push(PartVerdict {
            label: label.clone(),
            note,
            validity,
        });
    }
    Ok(Some(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n x n grid of quads on z = 0, two triangles each, consistently wound.
    pub(crate) fn grid(n: u32) -> MeshData {
        let mut m = MeshData::default();
        for y in 0..=n {
            for x in 0..=n {
                m.positions.push([x as f32, y as f32, 0.0]);
            }
        }
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                m.triangles.push([v, v + 1, v + n + 2]);
                m.triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        m
    }

    fn tetra() -> MeshData {
        MeshData {
            positions: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
    }

    #[test]
    fn closed_tetrahedron() {
        let t = analyse(&tetra());
        assert_eq!(
            t,
            Topology {
                triangles: 4,
                referenced_vertices: 4,
                edges: 6,
                euler: 2,
                components: 1,
                ..Topology::default()
            }
        );
    }

    #[test]
    fn open_grid_with_hole_and_defects() {
        let g = grid(3);
        let t = analyse(&g);
        assert_eq!(
            (t.edges, t.boundary_edges, t.boundary_loops, t.euler),
            (33, 12, 1, 1)
        );
        // Remove the middle quad: a second loop.
        let mut h = g.clone();
        h.triangles.drain(8..10);
        let t = analyse(&h);
        assert_eq!((t.boundary_edges, t.boundary_loops, t.euler), (16, 2, 0));
        assert_eq!(t.non_manifold_vertices, 0);

        let mut d = g.clone();
        d.triangles.push([0, 1, 5]); // duplicate of triangle 0, reversed order
        d.triangles.push([3, 3, 4]); // degenerate
        d.triangles.push([0, 1, 99]); // out of range
        d.triangles.push([1, 0, 5]); // duplicate, flipped: folds against triangle 0
        let t = analyse(&d);
        assert_eq!(t.duplicate_triangles, 2);
        assert_eq!(t.degenerate_triangles, 1);
        assert_eq!(t.out_of_range_triangles, 1);
        assert!(t.non_manifold_edges >= 2);
        assert!(t.folded_pairs >= 1);
    }

    #[test]
    fn pinched_vertex_and_touching_loops() {
        // Two triangles touching at vertex 0 only: one pinched vertex, two boundary loops.
        let m = MeshData {
            positions: vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [-1., 0., 0.],
                [-1., -1., 0.],
            ],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
        };
        let t = analyse(&m);
        assert_eq!(t.non_manifold_vertices, 1);
        assert_eq!(t.boundary_loops, 2);
        assert_eq!(t.components, 1);
        assert_eq!(t.euler, 5 - 6 + 2);
    }

    #[test]
    fn inconsistent_and_non_manifold_edges() {
        let mut m = grid(1);
        m.triangles[1] = [0, 2, 3]; // flipped: was [0, 3, 2]
        let t = analyse(&m);
        assert_eq!(t.inconsistent_edges, 1);
        assert_eq!(t.folded_pairs, 1); // coplanar, opposite normals
        m.positions.push([0.5, 0.5, 1.0]);
        m.triangles.push([0, 3, 4]);
        let t = analyse(&m);
        assert_eq!(t.non_manifold_edges, 1);
    }

    #[test]
    fn compare_flags_new_defects_only() {
        let g = grid(4);
        let v = compare(&g, &g);
        assert!(v.is_valid(), "{v}");
        // Removing the two triangles of one inner quad opens a hole: a new loop, new Euler.
        let mut h = g.clone();
        h.triangles.drain(10..12);
        let v = compare(&g, &h);
        assert!(!v.is_valid());
        assert_eq!(v.boundary_loops, (1, 2));
        assert!(!v.euler_unchanged());
        // A fold: move a vertex so that one triangle flips over its neighbour.
        let mut f = g.clone();
        f.positions[6] = [3.5, 3.5, 0.0];
        let v = compare(&g, &f);
        assert!(v.new_folded_pairs > 0 && !v.is_valid(), "{v}");
        // A pre-existing fold is not new.
        let v = compare(&f, &f);
        assert_eq!(v.new_folded_pairs, 0);
        // Out of range.
        let mut o = g.clone();
        o.triangles[0][2] = 1000;
        let v = compare(&g, &o);
        assert_eq!(v.out_of_range_triangles, 1);
        assert!(!v.is_valid());
    }

    #[test]
    fn compare_flags_a_new_pinch_but_not_an_old_one() {
        // A 4 x 4 grid; removing the two triangles around the middle of two opposite quads
        // that touch only at vertex 12 leaves a pinch there.
        let g = grid(4);
        let mut p = g.clone();
        // Quads (1,1) and (2,2) share only vertex 12 (= 2 * 5 + 2). Keep everything except
        // the quads (2,1) and (1,2), which join them through edges at 12.
        p.triangles.retain(|t| {
            let quad = |x: u32, y: u32| {
                let v = y * 5 + x;
                [v, v + 1, v + 6, v + 5]
                    .iter()
                    .filter(|i| t.contains(i))
                    .count()
                    == 3
            };
            !(quad(2, 1) || quad(1, 2))
        });
        assert_eq!(analyse(&p).non_manifold_vertices, 1);
        let v = compare(&g, &p);
        assert_eq!(v.new_pinched_vertices, 1, "{v}");
        assert!(v.defects.contains(&Defect::NewPinchedVertex { vertex: 12 }));
        // Already pinched in the input: may stay.
        let v = compare(&p, &p);
        assert!(v.is_valid(), "{v}");
    }

    #[test]
    fn shared_meshes_match_sources_md() {
        // (file, V, E, boundary edges, loops, non-manifold vertices, euler, components)
        let expect = [
            ("cow.obj", 2903, 8706, 0, 0, 1, 1, 1),
            ("stanford_bunny.obj", 34834, 104288, 223, 5, 0, -3, 1),
            ("camelhead.obj", 11381, 34084, 56, 1, 0, 1, 1),
            ("plate_holes.obj", 618, 1878, 0, 0, 0, -8, 1),
        ];
        for (name, v, e, be, bl, nmv, eu, c) in expect {
            let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../tests/fixtures")
                .join(name);
            let m = crate::io::load(&p).unwrap();
            let t = analyse(&m);
            assert_eq!(
                (
                    t.referenced_vertices,
                    t.edges,
                    t.boundary_edges,
                    t.boundary_loops,
                    t.non_manifold_vertices,
                    t.euler,
                    t.components
                ),
                (v, e, be, bl, nmv, eu, c),
                "{name}"
            );
            assert_eq!(
                t.non_manifold_edges + t.duplicate_triangles + t.degenerate_triangles,
                0
            );
            assert_eq!(t.inconsistent_edges, 0);
            assert!(compare(&m, &m).is_valid());
        }
    }
}
