//! Index types: `u16` or `u32`, for the caller's triangles and for the workspace's links.

/// An unsigned integer type used as a vertex index in triangles, or as a link inside a
/// [`Workspace`](crate::Workspace).
///
/// Implemented for `u16` and `u32` only. The largest value, [`Index::NIL`], is reserved as
/// "no link" inside the workspace, so a workspace with `u16` links addresses at most 65 535
/// vertices and 65 535 triangles.
pub trait Index: Copy + Eq + Ord + core::fmt::Debug + sealed::Sealed {
    /// Zero.
    const ZERO: Self;
    /// The largest value, reserved as "none".
    const NIL: Self;
    /// Number of distinct values below [`Index::NIL`].
    const COUNT: usize;
    /// Widens to `usize` (lossless on every supported target: `usize` is at least 32 bits).
    fn to_usize(self) -> usize;
    /// Narrows from `usize`; `None` if it does not fit below [`Index::NIL`].
    fn from_usize(v: usize) -> Option<Self>;
    /// Narrows from `usize`, which the caller has already checked is below [`Index::COUNT`].
    /// Out-of-range values become [`Index::NIL`] rather than panicking.
    #[inline]
    fn narrow(v: usize) -> Self {
        Self::from_usize(v).unwrap_or(Self::NIL)
    }
}

/// The caller's triangle buffer with its index type turned into a value: the engine is compiled
/// once for both index types and converts at this boundary, instead of being duplicated per
/// type (a second copy cost about 17 KB of flash).
pub enum Tris<'a> {
    /// `u16` triangles.
    U16(&'a mut [[u16; 3]]),
    /// `u32` triangles.
    U32(&'a mut [[u32; 3]]),
}

impl Tris<'_> {
    /// Number of triangles.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        match self {
            Tris::U16(t) => t.len(),
            Tris::U32(t) => t.len(),
        }
    }

    /// Triangle `t`'s vertices, widened.
    #[inline]
    pub(crate) fn get(&self, t: usize) -> Option<[usize; 3]> {
        match self {
            Tris::U16(s) => s.get(t).map(|x| x.map(usize::from)),
            Tris::U32(s) => s.get(t).map(|x| x.map(|v| v as usize)),
        }
    }

    /// Sets slot `k` of triangle `t` to vertex `v` (a vertex of the mesh, so it fits).
    #[inline]
    pub(crate) fn set(&mut self, t: usize, k: usize, v: usize) {
        match self {
            Tris::U16(s) => {
                if let Some(x) = s.get_mut(t).and_then(|x| x.get_mut(k)) {
                    *x = u16::try_from(v).unwrap_or(u16::MAX);
                }
            }
            Tris::U32(s) => {
                if let Some(x) = s.get_mut(t).and_then(|x| x.get_mut(k)) {
                    *x = u32::try_from(v).unwrap_or(u32::MAX);
                }
            }
        }
    }

    /// Writes triangle `t` as removed: `[v, v, v]` with its first vertex.
    #[inline]
    pub(crate) fn kill(&mut self, t: usize) {
        match self {
            Tris::U16(s) => {
                if let Some(x) = s.get_mut(t) {
                    *x = [x[0]; 3];
                }
            }
            Tris::U32(s) => {
                if let Some(x) = s.get_mut(t) {
                    *x = [x[0]; 3];
                }
            }
        }
    }

    /// Copies triangle `from` over triangle `to`.
    #[inline]
    pub(crate) fn copy(&mut self, from: usize, to: usize) {
        match self {
            Tris::U16(s) => {
                if let (Some(&x), true) = (s.get(from), to < s.len()) {
                    if let Some(y) = s.get_mut(to) {
                        *y = x;
                    }
                }
            }
            Tris::U32(s) => {
                if let (Some(&x), true) = (s.get(from), to < s.len()) {
                    if let Some(y) = s.get_mut(to) {
                        *y = x;
                    }
                }
            }
        }
    }
}

mod sealed {
    use super::Tris;

    pub trait Sealed: Sized {
        /// The buffer as a [`Tris`].
        fn tris(t: &mut [[Self; 3]]) -> Tris<'_>;
        /// The buffer behind a [`Tris`] of this type (empty for the other type, which the
        /// engine never pairs with this one).
        fn slice<'b>(t: &'b Tris<'_>) -> &'b [[Self; 3]];
    }

    impl Sealed for u16 {
        fn tris(t: &mut [[u16; 3]]) -> Tris<'_> {
            Tris::U16(t)
        }
        fn slice<'b>(t: &'b Tris<'_>) -> &'b [[u16; 3]] {
            match t {
                Tris::U16(s) => s,
                Tris::U32(_) => &[],
            }
        }
    }

    impl Sealed for u32 {
        fn tris(t: &mut [[u32; 3]]) -> Tris<'_> {
            Tris::U32(t)
        }
        fn slice<'b>(t: &'b Tris<'_>) -> &'b [[u32; 3]] {
            match t {
                Tris::U32(s) => s,
                Tris::U16(_) => &[],
            }
        }
    }
}

impl Index for u16 {
    const ZERO: Self = 0;
    const NIL: Self = u16::MAX;
    const COUNT: usize = u16::MAX as usize;
    #[inline]
    fn to_usize(self) -> usize {
        self as usize
    }
    #[inline]
    fn from_usize(v: usize) -> Option<Self> {
        if v < Self::COUNT {
            Some(v as u16)
        } else {
            None
        }
    }
}

impl Index for u32 {
    const ZERO: Self = 0;
    const NIL: Self = u32::MAX;
    const COUNT: usize = u32::MAX as usize;
    #[inline]
    fn to_usize(self) -> usize {
        self as usize
    }
    #[inline]
    fn from_usize(v: usize) -> Option<Self> {
        if v < Self::COUNT {
            Some(v as u32)
        } else {
            None
        }
    }
}
