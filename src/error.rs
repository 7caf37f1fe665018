//! Why a mesh was not simplified: the typed errors of every entry point.

use crate::index::Index;

/// Which capacity an input exceeded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Capacity {
    /// More positions than the [`Storage`](crate::Storage) (or its link type) can number.
    Vertices,
    /// More triangles than the [`Storage`](crate::Storage) (or its link type) can number.
    Triangles,
    /// Fewer stored quadrics than positions ([`StoredQuadric`](crate::StoredQuadric)), or
    /// fewer attribute states or attribute values
    /// ([`AttributeQuadric`](crate::cost::AttributeQuadric)).
    Quadrics,
    /// Fewer control links than [`bound::control_len`](crate::bound::control_len), or more control points than the
    /// link type numbers ([`Controls`](crate::Controls)).
    Controls,
    /// Fewer shell pairs than positions, or fewer index words than `2·T + 2`
    /// ([`Envelope`](crate::Envelope)).
    Envelope,
}

impl core::fmt::Display for Capacity {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Capacity::Vertices => "vertices",
            Capacity::Triangles => "triangles",
            Capacity::Quadrics => "stored quadrics",
            Capacity::Controls => "control links",
            Capacity::Envelope => "envelope storage",
        })
    }
}

/// Which configuration field is out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub enum ConfigField {
    /// [`Target::Ratio`](crate::Target::Ratio) outside `[0, 1]`.
    Target,
    MaxCost,
    MaxPasses,
    Lambda,
    MaxNormalTurn,
    MinQuality,
    BoundaryWeight,
    MaxError,
    /// [`Config::error_limit`](crate::Config::error_limit) negative or NaN, or finite with
    /// the passes schedule or with [`TriangleCollapse`](crate::TriangleCollapse).
    ErrorLimit,
    ControlAngle,
    /// [`TriangleCollapse`](crate::TriangleCollapse) or
    /// [`VertexDecimation`](crate::VertexDecimation) with another schedule than greedy, or
    /// `VertexDecimation` with an error bound.
    Operator,
    /// The schedule cannot run this cost ([`StoredQuadric`](crate::StoredQuadric): greedy or
    /// batched only), or [`Schedule::Batched`](crate::Schedule::Batched) without the crate
    /// feature `batched`.
    Schedule,
    /// Optimal placement without [`Positions::Write`](crate::Positions::Write), or with an error bound (its control
    /// points are read at the positions placement would move).
    Placement,
    /// [`Config::cost`](crate::Config::cost) names another cost than the one given to [`Storage::start`](crate::Storage::start).
    Cost,
    /// Removing whole parts (`Simplifier::with_parts`, crate feature `parts`) with the passes
    /// schedule, an error bound or a collapse log, or asked for after the first step.
    Parts,
}

/// Why a mesh was not simplified. Every error is returned before the caller's triangle buffer
/// is modified.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// The mesh does not fit the workspace.
    Capacity {
        /// Vertices or triangles.
        what: Capacity,
        /// How many the mesh has.
        needed: usize,
        /// How many the workspace takes.
        available: usize,
    },
    /// A triangle refers to a vertex past the end of `positions`.
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The offending index.
        index: usize,
    },
    /// A vertex used by a triangle has a NaN or infinite coordinate.
    NonFinitePosition {
        /// The vertex.
        vertex: usize,
    },
    /// A used vertex of an integer run has a coordinate at or above
    /// `pipeline::integer::GRID` (the grid has 15 bits; `pipeline::quantise` puts a float
    /// mesh on it).
    OffGrid {
        /// The vertex.
        vertex: usize,
    },
    /// A configuration value is out of range.
    InvalidConfig {
        /// The field.
        field: ConfigField,
    },
    /// The original triangles given for an error bound are not the triangles to simplify:
    /// another length (`triangle` is then the shorter length) or a different triangle.
    OriginalMismatch {
        /// The first triangle that differs.
        triangle: usize,
    },
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::Capacity {
                what,
                needed,
                available,
            } => {
                let holds = match what {
                    Capacity::Vertices | Capacity::Triangles => "the workspace holds",
                    Capacity::Quadrics => "there are",
                    Capacity::Controls | Capacity::Envelope => "there are",
                };
                write!(f, "mesh needs {needed} {what} but {holds} {available}")?;
                if matches!(what, Capacity::Vertices | Capacity::Triangles)
                    && *available == <u16 as Index>::COUNT
                    && *needed > *available
                {
                    f.write_str(" (u16 links number at most 65535: use u32 links)")?;
                }
                Ok(())
            }
            Error::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} refers to missing vertex {index}")
            }
            Error::NonFinitePosition { vertex } => {
                write!(f, "vertex {vertex} has a non-finite coordinate")
            }
            Error::OffGrid { vertex } => {
                write!(f, "vertex {vertex} has a coordinate off the 15-bit grid (32768 or more)")
            }
            Error::InvalidConfig { field } => match field {
                ConfigField::MaxError => write!(
                    f,
                    "configuration field MaxError is out of range (non-negative; a finite bound \
                     needs bound::Controls)"
                ),
                ConfigField::Schedule => write!(
                    f,
                    "configuration field Schedule: stored quadrics run the greedy or batched \
                     schedule only, and the batched schedule needs the crate feature `batched`"
                ),
                ConfigField::Placement => write!(
                    f,
                    "configuration field Placement: optimal placement needs writable positions \
                     and no error bound"
                ),
                ConfigField::Cost => write!(
                    f,
                    "configuration field Cost names another cost than the one given"
                ),
                ConfigField::Parts => write!(
                    f,
                    "configuration field Parts: removing parts needs the greedy or batched schedule, no \
                     error bound and no collapse log, before the first step"
                ),
                _ => write!(f, "configuration field {field:?} is out of range"),
            },
            Error::OriginalMismatch { triangle } => {
                write!(f, "original triangle {triangle} is not the one to simplify")
            }
        }
    }
}
