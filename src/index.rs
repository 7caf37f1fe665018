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

mod sealed {
    pub trait Sealed {}
    impl Sealed for u16 {}
    impl Sealed for u32 {}
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
