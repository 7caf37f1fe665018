//! Where the clustering reads its input: a re-readable stream of triangles ([`Source`]) and
//! the positions of their vertices ([`PositionSource`]).

use super::{to_u32, ClusterError};
use crate::index::Index;
use crate::math::V3;

/// Read access to vertex positions: a slice, or any accessor (flash, a file, a link) through
/// [`PositionFn`]. `None` means the vertex does not exist.
pub trait PositionSource {
    /// The position of `vertex`.
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]>;
}

impl PositionSource for &[[f32; 3]] {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.get(vertex).copied()
    }
}

/// A closure as a [`PositionSource`] accessor.
pub struct PositionFn<F>(pub F);

impl<F: FnMut(usize) -> Option<[f32; 3]>> PositionSource for PositionFn<F> {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        (self.0)(vertex)
    }
}

/// A stream of triangles that can be read again from the start, with their positions: what
/// [`Clusterer::cluster`](super::Clusterer::cluster) needs for the bounding box, the search for a target count and the
/// quadric representative. A stream that can be read only once goes through
/// [`Clusterer::stream`](super::Clusterer::stream) instead.
pub trait Source {
    /// Goes back to the first triangle; `false` if the source cannot.
    fn rewind(&mut self) -> bool;
    /// Copies the next triangles into `buf`; returns how many (0: the end).
    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize;
    /// The position of `vertex` (`None`: no such vertex).
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]>;
}

/// A [`Source`] over triangles and positions in memory (or flash).
pub struct SliceSource<'a, I: Index> {
    positions: &'a [[f32; 3]],
    triangles: &'a [[I; 3]],
    at: usize,
}

impl<'a, I: Index> SliceSource<'a, I> {
    /// A source reading `triangles` from the start.
    pub fn new(positions: &'a [[f32; 3]], triangles: &'a [[I; 3]]) -> Self {
        SliceSource {
            positions,
            triangles,
            at: 0,
        }
    }
}

impl<I: Index> Source for SliceSource<'_, I> {
    fn rewind(&mut self) -> bool {
        self.at = 0;
        true
    }
    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize {
        let rest = self.triangles.get(self.at..).unwrap_or(&[]);
        let mut n = 0;
        for (d, s) in buf.iter_mut().zip(rest) {
            *d = [
                to_u32(s[0].to_usize()),
                to_u32(s[1].to_usize()),
                to_u32(s[2].to_usize()),
            ];
            n += 1;
        }
        self.at += n;
        n
    }
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.positions.get(vertex).copied()
    }
}

/// The three corners' positions of triangle number `index`, checked.
#[inline]
pub(super) fn corners<P: PositionSource + ?Sized>(
    pos: &mut P,
    t: &[u32; 3],
    index: usize,
) -> Result<[V3; 3], ClusterError> {
    Ok([
        checked_position(pos, t[0], index)?,
        checked_position(pos, t[1], index)?,
        checked_position(pos, t[2], index)?,
    ])
}

/// The position of vertex `v` (a corner of triangle number `index`), checked.
#[inline]
pub(super) fn checked_position<P: PositionSource + ?Sized>(
    pos: &mut P,
    v: u32,
    index: usize,
) -> Result<V3, ClusterError> {
    let p = pos
        .position(v as usize)
        .ok_or(ClusterError::IndexOutOfRange {
            triangle: index,
            index: v as usize,
        })?;
    if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
        return Err(ClusterError::NonFinitePosition { vertex: v as usize });
    }
    Ok(p)
}

pub(super) struct SourcePositions<'s, S>(pub(super) &'s mut S);

impl<S: Source> PositionSource for SourcePositions<'_, S> {
    #[inline]
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        self.0.position(vertex)
    }
}
