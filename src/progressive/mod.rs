//! Progressive meshes: the collapses of a simplification turned into vertex splits, and a
//! level-of-detail slider that moves between levels in place.
//!
//! Cheng, Pan and Shi 1998 ("A fast algorithm for generating progressive meshes") §2.1-2.2:
//! the input `M = Mⁿ` is simplified by edge collapses to a base mesh `M⁰`, and each collapse
//! is undone by a vertex split, so `M⁰ → M¹ → … → Mⁿ` recovers the input exactly. Here a
//! collapse keeps one endpoint (subset placement, Lin 2007 §2), so a split needs no new
//! position on the device.
//!
//! # Layout
//! [`Progressive::from_log`] rearranges the input once:
//! - **Vertices** are renumbered: the base mesh's vertices first (in input order), then the
//!   removed vertices in reverse collapse order (Cheng, Pan and Shi 1998 name them `m₀+i+1`),
//!   so split `j` always creates vertex `m₀ + j` and a record need not name it. `order[new] =
//!   input index` finds the positions, which stay where they are (they may be in flash).
//! - **Triangles**: the base mesh first (in input order), then the triangles each split
//!   restores, in split order. Every level is a prefix of the buffer, so a split or a collapse
//!   only moves the end of the prefix and rewrites the corners that change vertex.
//!
//! # Adjacency
//! Each vertex keeps a singly linked list of its triangles *sorted by slot, largest first*.
//! The order is a function of the current triangles alone (not of the history), which is what
//! lets a split name the corners that move by their positions in the kept vertex's list:
//! [`Split::moved`] is a bit mask over that list. A split takes the masked corners out of
//! `s`'s list (they stay sorted) and puts the restored triangles, whose slots are the largest,
//! at the heads of their corners' lists: O(1) each, where an ascending order would walk every
//! list to its end. A collapse unlinks those same triangles from the heads, and merges two
//! sorted lists. Both are O(valence) (decision record: docs/progressive.md).
//!
//! Memory: the triangle buffer, one link per corner and one list head per vertex (for `u16`:
//! 12 bytes per input triangle and 2 per vertex), plus 16 bytes per [`Split`].

use crate::index::Index;
use lists::Lists;

mod from_log;
pub(crate) mod lists;
pub mod stream;

/// One vertex split (the inverse of one logged collapse). Split `j` creates vertex `m₀ + j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split<I> {
    /// The vertex that stays (`s` of Cheng, Pan and Shi's `vsplit(s, l, r)`), in the new numbering.
    pub kept: I,
    /// Triangles the split restores: 2 for an interior edge, 1 for a boundary edge. They sit
    /// in the buffer right after the level's prefix.
    pub restored: u8,
    /// Which of `kept`'s triangles, counted in its list (by slot, largest first), go to the
    /// new vertex: bit `p` for the `p`-th.
    pub moved: u64,
}

impl<I: Index> Split<I> {
    /// A placeholder to fill a buffer with.
    pub const EMPTY: Self = Split {
        kept: I::ZERO,
        restored: 0,
        moved: 0,
    };
}

/// Why a collapse log could not be turned into vertex splits, or a progressive mesh not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ProgressiveError {
    /// A buffer of the storage is too small.
    Capacity {
        /// Which buffer (`"triangles"`, `"links"`, `"heads"`, `"order"`, `"scratch"`,
        /// `"splits"`).
        what: &'static str,
        /// Entries needed.
        needed: usize,
        /// Entries given.
        available: usize,
    },
    /// A triangle refers to a vertex at or past `vertex_count`.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
    },
    /// Log entry `entry` is not a collapse of the mesh at that point (a vertex out of range
    /// or already removed, not an edge, more than two triangles on the edge, or a vertex left
    /// without triangles).
    BadLog {
        /// The entry.
        entry: usize,
    },
    /// The kept vertex of log entry `entry` has more than 64 triangles after the collapse and
    /// one that the split moves lies past the 64th of its list, which [`Split::moved`] cannot
    /// name. (A kept vertex of any valence is fine while the moved triangles are among its
    /// first 64.)
    ValenceTooHigh {
        /// The entry.
        entry: usize,
    },
}

impl core::fmt::Display for ProgressiveError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ProgressiveError::Capacity {
                what,
                needed,
                available,
            } => write!(f, "{what}: {needed} needed, {available} given"),
            ProgressiveError::IndexOutOfRange { triangle } => {
                write!(f, "triangle {triangle} refers to a missing vertex")
            }
            ProgressiveError::BadLog { entry } => {
                write!(f, "log entry {entry} is not a collapse of the mesh")
            }
            ProgressiveError::ValenceTooHigh { entry } => {
                write!(
                    f,
                    "log entry {entry}: a triangle the split moves lies past the 64th of the kept vertex's"
                )
            }
        }
    }
}

/// Caller-provided memory of a [`Progressive`].
pub struct Storage<'a, I: Index> {
    /// Triangles: at least the input's count.
    pub triangles: &'a mut [[I; 3]],
    /// One link per corner: as many entries as `triangles`.
    pub links: &'a mut [[I; 3]],
    /// One list head per vertex: at least the vertex count.
    pub heads: &'a mut [I],
    /// One record per vertex split: at least the number of collapses.
    pub splits: &'a mut [Split<I>],
}

/// A progressive mesh over caller-provided storage: the slider between its base mesh and the
/// full mesh. Every level is a prefix of [`Progressive::triangles`].
pub struct Progressive<'a, I: Index> {
    pub(crate) lists: Lists<'a, I>,
    pub(crate) splits: &'a mut [Split<I>],
    /// Vertices and triangles of the base mesh.
    pub(crate) base_vertices: usize,
    pub(crate) base_triangles: usize,
    /// Splits known (all of them after `from_log`; so far received when decoding).
    pub(crate) known: usize,
    /// Triangles of the finest known level.
    pub(crate) top_triangles: usize,
    /// Splits applied now.
    pub(crate) level: usize,
    /// Live triangles now.
    pub(crate) live: usize,
}

impl<'a, I: Index> Progressive<'a, I> {
    /// An empty progressive mesh (for the stream decoder to fill).
    pub(crate) fn empty(storage: Storage<'a, I>) -> Self {
        let Storage {
            triangles,
            links,
            heads,
            splits,
        } = storage;
        heads.fill(I::NIL);
        let n = triangles.len().min(links.len()).min(I::COUNT);
        let tris = triangles.get_mut(..n).unwrap_or_default();
        let next = links.get_mut(..n).unwrap_or_default();
        Progressive {
            lists: Lists::new(tris, next, heads),
            splits,
            base_vertices: 0,
            base_triangles: 0,
            known: 0,
            top_triangles: 0,
            level: 0,
            live: 0,
        }
    }

    /// Vertices the storage can number.
    pub(crate) fn vertex_capacity(&self) -> usize {
        self.lists.head.len().min(I::COUNT)
    }

    /// Triangles the storage holds.
    pub(crate) fn triangle_capacity(&self) -> usize {
        self.lists.tris.len()
    }

    /// Vertex splits the storage holds.
    pub(crate) fn split_capacity(&self) -> usize {
        self.splits.len()
    }

    /// Starts an empty base mesh over `base_vertices` vertices.
    pub(crate) fn start(&mut self, base_vertices: usize) {
        self.base_vertices = base_vertices;
    }

    /// Appends a base triangle; `false` if it does not fit or is not a triangle of the base
    /// vertices.
    pub(crate) fn push_base(&mut self, tri: [I; 3]) -> bool {
        let [a, b, c] = tri.map(|i| i.to_usize());
        if self.known > 0
            || a == b
            || b == c
            || a == c
            || a.max(b).max(c) >= self.base_vertices
            || self.live >= self.lists.tris.len()
        {
            return false;
        }
        if let Some(slot) = self.lists.tris.get_mut(self.live) {
            *slot = tri;
        }
        self.lists.link(self.live);
        self.live += 1;
        self.base_triangles += 1;
        self.top_triangles += 1;
        true
    }

    /// Appends a vertex split (creating vertex `base + levels`) with the triangles it
    /// restores, and applies it; `false` if it does not fit the storage.
    pub(crate) fn push_split(&mut self, split: Split<I>, restored: &[[I; 3]]) -> bool {
        self.refine(usize::MAX);
        let t = self.base_vertices + self.known;
        let top = self.top_triangles;
        if t >= self.vertex_capacity()
            || self.known >= self.splits.len()
            || top + restored.len() > self.lists.tris.len()
            || restored.len() != split.restored as usize
            || split.kept.to_usize() >= t
        {
            return false;
        }
        for (u, tri) in restored.iter().enumerate() {
            if let Some(slot) = self.lists.tris.get_mut(top + u) {
                *slot = *tri;
            }
        }
        if let Some(slot) = self.splits.get_mut(self.known) {
            *slot = split;
        }
        self.known += 1;
        self.top_triangles += restored.len();
        self.refine(1) == 1
    }

    /// Applies up to `n` vertex splits (finer); returns how many it applied.
    pub fn refine(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.level < self.known {
            let Some(&sp) = self.splits.get(self.level) else {
                break;
            };
            let t = self.base_vertices + self.level;
            self.lists.part(sp.kept.to_usize(), t, sp.moved);
            for u in self.live..self.live + sp.restored as usize {
                self.lists.link(u);
            }
            self.live += sp.restored as usize;
            self.level += 1;
            done += 1;
        }
        done
    }

    /// Applies up to `n` edge collapses (coarser); returns how many it applied.
    pub fn coarsen(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.level > 0 {
            let Some(&sp) = self.splits.get(self.level - 1) else {
                break;
            };
            let t = self.base_vertices + self.level - 1;
            let r = sp.restored as usize;
            if r > self.live {
                break;
            }
            for u in self.live - r..self.live {
                self.lists.unlink_triangle(u);
            }
            self.lists.merge(t, sp.kept.to_usize());
            self.live -= r;
            self.level -= 1;
            done += 1;
        }
        done
    }

    /// Goes to the finest level with at most `triangles` triangles (the base mesh if it has
    /// more): the mesh the simplifier had when it first reached that count.
    pub fn set_level(&mut self, triangles: usize) {
        while self.live > triangles && self.coarsen(1) == 1 {}
        while self.level < self.known {
            let r = self
                .splits
                .get(self.level)
                .map_or(usize::MAX, |s| s.restored as usize);
            if self.live + r > triangles || self.refine(1) == 0 {
                break;
            }
        }
    }

    /// The current level's triangles (new vertex numbers).
    pub fn triangles(&self) -> &[[I; 3]] {
        self.lists.tris.get(..self.live).unwrap_or(&[])
    }

    /// Vertices of the current level: numbers `0..vertices()` are in use.
    pub fn vertices(&self) -> usize {
        self.base_vertices + self.level
    }

    /// Vertex splits applied now (0: the base mesh).
    pub fn level(&self) -> usize {
        self.level
    }

    /// Vertex splits known: the finest level.
    pub fn levels(&self) -> usize {
        self.known
    }

    /// Triangles of the base mesh.
    pub fn base_triangles(&self) -> usize {
        self.base_triangles
    }

    /// Vertices of the base mesh.
    pub fn base_vertices(&self) -> usize {
        self.base_vertices
    }

    /// Triangles of the finest known level.
    pub fn full_triangles(&self) -> usize {
        self.top_triangles
    }

    /// The vertex splits (the first [`Progressive::levels`] are meaningful).
    pub fn splits(&self) -> &[Split<I>] {
        self.splits.get(..self.known).unwrap_or(&[])
    }
}
