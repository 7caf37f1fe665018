//! Compacting the vertex buffers after a run: drop the vertices no triangle uses, renumber the
//! rest, and move every attribute stream (normals, texture coordinates, colours, bone weights,
//! any `Copy` type per vertex) to match, in place.
//!
//! With subset placement (every run but one with `Placement::Optimal` and
//! `Positions::Write`) each vertex of the result is an input vertex, and the library never
//! reads or writes anything but positions and triangles: the caller's attribute buffers stay
//! exactly right for the result as long as they are kept, indexed like the positions. Nothing here is needed to
//! draw the result. These two functions are for firmware that wants the vertex buffers of
//! the result packed, like meshoptimizer's `meshopt_optimizeVertexFetchRemap` followed by
//! `meshopt_remapVertexBuffer`, but without a second buffer:
//!
//! 1. [`compact_vertices`] renumbers the triangles and writes the old-to-new map into the
//!    caller's `remap` (one index per input vertex, [`Index::NIL`] for the unused ones).
//! 2. [`remap_in_place`] on each stream (positions included, if they are in RAM) moves each
//!    kept element to its new slot; the stream's first `n` elements are then the result's.
//!
//! The new number of a vertex is its rank among the used vertices in ascending old order, not
//! the order of first use: so every new index is at most its old one, and one forward sweep
//! moves the elements without overwriting one not yet moved (first-use order does not have
//! this property: the first triangle `[5, 0, 1]` makes vertex 5 new vertex 0 and vertex 0 new
//! vertex 1). The cost is that the result is not reordered for the vertex cache.
//!
//! Optimal placement (`Placement::Optimal` with `Positions::Write`) moves the kept vertex of
//! each collapse to a new position and does not interpolate attributes: the moved vertex
//! keeps the attributes of the input vertex whose slot it occupies. That is why
//! `tinydecimate simplify` refuses `--placement optimal` on a mesh with attributes.
//!
//! Both functions are generic and hold no state: a firmware that does not call them carries
//! none of their code. No heap, no panics: every index is checked before anything is written.
//!
//! ```
//! use tinydecimate::remap::{compact_vertices, remap_in_place};
//!
//! // Vertices 1 and 3 are unused after a simplification.
//! let mut triangles = [[4u16, 0, 2], [2, 0, 5]];
//! let mut positions = [[0.0f32; 3], [1.0; 3], [2.0; 3], [3.0; 3], [4.0; 3], [5.0; 3]];
//! let mut uvs = [[0.0f32, 0.0], [0.1, 0.1], [0.2, 0.2], [0.3, 0.3], [0.4, 0.4], [0.5, 0.5]];
//! let mut remap = [0u16; 6];
//! let n = compact_vertices(&mut triangles, &mut remap)?;
//! assert_eq!(n, 4);
//! assert_eq!(remap, [0, u16::MAX, 1, u16::MAX, 2, 3]);
//! assert_eq!(triangles, [[2, 0, 1], [1, 0, 3]]);
//! remap_in_place(&mut positions, &remap)?;
//! remap_in_place(&mut uvs, &remap)?;
//! assert_eq!(&uvs[..n], &[[0.0, 0.0], [0.2, 0.2], [0.4, 0.4], [0.5, 0.5]]);
//! assert_eq!(positions[3], [5.0; 3]);
//! # Ok::<(), tinydecimate::remap::RemapError>(())
//! ```

use crate::index::Index;

/// Why a compaction was refused. Nothing was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RemapError {
    /// `remap` has more entries than the index type numbers below [`Index::NIL`].
    TooManyVertices {
        /// Entries of `remap`.
        vertices: usize,
        /// Largest count the index type takes.
        available: usize,
    },
    /// A triangle refers to a vertex past the end of `remap`.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending index.
        index: usize,
    },
    /// The stream does not have one element per entry of `remap`.
    StreamLength {
        /// Entries of `remap`.
        expected: usize,
        /// Elements of the stream.
        found: usize,
    },
    /// `remap` is not a map [`compact_vertices`] writes: the kept vertices are not numbered
    /// 0, 1, 2, ... in ascending old order. `vertex` is the first old index that breaks it.
    NotCompacting {
        /// The vertex.
        vertex: usize,
    },
}

impl core::fmt::Display for RemapError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RemapError::TooManyVertices {
                vertices,
                available,
            } => write!(
                f,
                "{vertices} vertices but the index type numbers {available}"
            ),
            RemapError::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} refers to missing vertex {index}")
            }
            RemapError::StreamLength { expected, found } => {
                write!(f, "stream has {found} elements, the remap {expected}")
            }
            RemapError::NotCompacting { vertex } => {
                write!(
                    f,
                    "remap entry of vertex {vertex} is not its rank among the kept"
                )
            }
        }
    }
}

/// Renumbers the vertices `triangles` use as 0, 1, 2, ... in ascending order of their old
/// index, rewrites `triangles` with the new numbers and writes the map into `remap`:
/// `remap[old]` is the new index, or [`Index::NIL`] when no triangle uses `old`. `remap` has
/// one entry per input vertex. Returns the number of vertices kept; the new index of every
/// vertex is at most its old one.
///
/// Errors (nothing written to either slice): a triangle index at or past `remap.len()`, or
/// `remap.len()` above [`Index::COUNT`].
pub fn compact_vertices<I: Index>(
    triangles: &mut [[I; 3]],
    remap: &mut [I],
) -> Result<usize, RemapError> {
    if remap.len() > I::COUNT {
        return Err(RemapError::TooManyVertices {
            vertices: remap.len(),
            available: I::COUNT,
        });
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|v| v.to_usize() >= remap.len()) {
            return Err(RemapError::IndexOutOfRange {
                triangle: t,
                index: v.to_usize(),
            });
        }
    }
    remap.fill(I::NIL);
    for tri in triangles.iter() {
        for &v in tri {
            if let Some(r) = remap.get_mut(v.to_usize()) {
                *r = I::ZERO;
            }
        }
    }
    let mut kept = 0usize;
    for r in remap.iter_mut() {
        if *r != I::NIL {
            // `kept` < remap.len() <= I::COUNT: it fits below NIL.
            *r = I::narrow(kept);
            kept += 1;
        }
    }
    for tri in triangles.iter_mut() {
        for v in tri.iter_mut() {
            if let Some(&r) = remap.get(v.to_usize()) {
                *v = r;
            }
        }
    }
    Ok(kept)
}

/// Moves each element of `stream` whose vertex [`compact_vertices`] kept to its new slot:
/// afterwards `stream[remap[old]]` is the old `stream[old]` for every kept `old`, and the
/// first `n` elements (`n` as [`compact_vertices`] returned) are the compacted stream. The
/// elements past `n` are left over from the input. Call it once per attribute stream.
///
/// Errors (nothing written): `stream` and `remap` of different lengths, or a `remap` that is
/// not the ascending-rank map of [`compact_vertices`] (checked first, so any other map is
/// refused rather than half applied).
pub fn remap_in_place<T: Copy, I: Index>(
    stream: &mut [T],
    remap: &[I],
) -> Result<usize, RemapError> {
    if stream.len() != remap.len() {
        return Err(RemapError::StreamLength {
            expected: remap.len(),
            found: stream.len(),
        });
    }
    let mut kept = 0usize;
    for (old, &r) in remap.iter().enumerate() {
        if r != I::NIL {
            if r.to_usize() != kept {
                return Err(RemapError::NotCompacting { vertex: old });
            }
            kept += 1;
        }
    }
    // new <= old for every kept vertex, and new indices increase with old ones: slot `new` is
    // either `old` itself or a slot whose element was already moved (or is unused).
    for old in 0..remap.len() {
        if let Some(&r) = remap.get(old) {
            if r != I::NIL {
                if let Some(&x) = stream.get(old) {
                    if let Some(slot) = stream.get_mut(r.to_usize()) {
                        *slot = x;
                    }
                }
            }
        }
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn compacts_and_moves_streams() {
        let mut tris = [[5u32, 0, 1], [1, 5, 3]];
        let mut remap = [7u32; 7];
        assert_eq!(compact_vertices(&mut tris, &mut remap), Ok(4));
        let nil = u32::MAX;
        assert_eq!(remap, [0, 1, nil, 2, nil, 3, nil]);
        assert_eq!(tris, [[3, 0, 1], [1, 3, 2]]);
        let mut attr = [10u8, 11, 12, 13, 14, 15, 16];
        assert_eq!(remap_in_place(&mut attr, &remap), Ok(4));
        assert_eq!(&attr[..4], &[10, 11, 13, 15]);
    }

    #[test]
    fn refuses_bad_input_without_writing() {
        let mut tris = [[0u16, 1, 2], [0, 2, 9]];
        let mut remap = [3u16; 4];
        assert_eq!(
            compact_vertices(&mut tris, &mut remap),
            Err(RemapError::IndexOutOfRange {
                triangle: 1,
                index: 9
            })
        );
        assert_eq!(tris, [[0, 1, 2], [0, 2, 9]]);
        assert_eq!(remap, [3; 4]);

        let mut stream = [1u8, 2, 3];
        assert_eq!(
            remap_in_place(&mut stream, &[0u16, 1]),
            Err(RemapError::StreamLength {
                expected: 2,
                found: 3
            })
        );
        // A permutation is not a compaction: refused before any element moves.
        assert_eq!(
            remap_in_place(&mut stream, &[1u16, 0, 2]),
            Err(RemapError::NotCompacting { vertex: 0 })
        );
        assert_eq!(
            remap_in_place(&mut stream, &[0u16, u16::MAX, 2]),
            Err(RemapError::NotCompacting { vertex: 2 })
        );
        assert_eq!(stream, [1, 2, 3]);

        let mut big = std::vec![0u16; u16::COUNT + 1];
        assert_eq!(
            compact_vertices(&mut [[0u16, 1, 2]], &mut big),
            Err(RemapError::TooManyVertices {
                vertices: u16::COUNT + 1,
                available: u16::COUNT
            })
        );
    }

    #[test]
    fn empty_triangles_keep_nothing() {
        let mut remap = [0u16; 3];
        assert_eq!(compact_vertices::<u16>(&mut [], &mut remap), Ok(0));
        assert_eq!(remap, [u16::MAX; 3]);
    }

    proptest! {
        /// Against a plain copy into a fresh buffer: the same triangles (as attribute
        /// values) and the same compacted stream, for any triangles over any vertex count.
        #[test]
        fn matches_a_copying_compaction(
            n in 1usize..60,
            raw in proptest::collection::vec((0usize..60, 0usize..60, 0usize..60), 0..40),
        ) {
            let tris: std::vec::Vec<[u16; 3]> =
                raw.iter().map(|&(a, b, c)| [(a % n) as u16, (b % n) as u16, (c % n) as u16]).collect();
            // Each vertex's attribute is a value derived from its old index.
            let attr: std::vec::Vec<u32> = (0..n as u32).map(|i| i * 7 + 3).collect();
            let mut used: std::vec::Vec<usize> = tris.iter().flatten().map(|&v| usize::from(v)).collect();
            used.sort_unstable();
            used.dedup();
            let mut t2 = tris.clone();
            let mut remap = std::vec![0u16; n];
            let kept = compact_vertices(&mut t2, &mut remap).unwrap();
            prop_assert_eq!(kept, used.len());
            let mut stream = attr.clone();
            prop_assert_eq!(remap_in_place(&mut stream, &remap), Ok(kept));
            let copied: std::vec::Vec<u32> = used.iter().map(|&v| attr[v]).collect();
            prop_assert_eq!(&stream[..kept], &copied[..]);
            for (a, b) in tris.iter().zip(&t2) {
                for k in 0..3 {
                    prop_assert!(usize::from(b[k]) < kept);
                    prop_assert!(b[k] <= a[k]);
                    prop_assert_eq!(stream[usize::from(b[k])], attr[usize::from(a[k])]);
                }
            }
        }
    }
}
