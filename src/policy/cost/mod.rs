//! Collapse costs: how much moving one vertex onto a neighbour changes the surface.
//!
//! The engine prices a vertex's collapses in one walk around its fan. Each triangle of the fan
//! is handed to [`Cost::add`] (its unit normal and twice its area), building a small summary
//! of the fan on the stack, then each candidate target is priced from that summary by
//! [`Cost::price`] in O(1). A cost that needs every surviving triangle's *new* normal (the
//! paper's W) says so with [`Cost::needs_turn`]; the engine then walks the fan once more per
//! candidate and passes the summed normal change. A new cost is one more implementation of this
//! trait, passed to [`Storage::start`](crate::Storage::start); the engine does not change.
//!
//! The built-in costs take their settings (boundary weight, schedule) from the [`Config`] when
//! the run starts ([`Cost::configure`]), so each setting is given once.
//!
//! All lengths are in the engine's normalised units (the input's bounding box mapped to about
//! `[-1, 1]³`), so costs do not depend on the scale of the input.

use crate::math::V3;
pub use crate::quadric::{error, VertexQuadric};

mod attributes;
mod builtin;
mod energy;
mod memoryless;
mod stored;
mod variation;

use crate::{Config, ConfigField, Error};
pub use attributes::{AttributeQuadric, AttributeState};
pub use builtin::Builtin;
pub use energy::{Energy, EnergyFan, Samples};
pub use memoryless::{Quadric, QuadricFan};
pub use stored::{Placement, StoredQuadric};
pub use variation::NormalVariation;

/// `Error::InvalidConfig` for `field`.
fn bad(field: ConfigField) -> Result<(), Error> {
    Err(Error::InvalidConfig { field })
}

/// One candidate collapse `from -> to`, as a cost sees it.
#[derive(Clone, Copy, Debug)]
pub struct Move {
    /// How far the moving vertex moves (`to - from`).
    pub d: [f32; 3],
    /// For a boundary vertex moving along its boundary: squared distance from it to the new
    /// boundary edge, i.e. how far the boundary retreats. Zero otherwise.
    pub retreat2: f32,
    /// Σ ‖N_new − N_old‖² over the surviving triangles (unit normals; Lin 2007 eq. 2), when
    /// [`Cost::needs_turn`]; zero otherwise.
    pub turn: f32,
    /// The moving vertex (removed by the collapse).
    pub from: usize,
    /// The kept vertex.
    pub to: usize,
    /// Their positions (normalised units).
    pub p_from: V3,
    /// See `p_from`.
    pub p_to: V3,
    /// The kept vertex must stay where it is (it is a feature vertex, or positions are
    /// read-only): a placing cost prices the move at `p_to`.
    pub keep: bool,
}

/// A collapse cost. Lower is better; the engine never performs a collapse whose price is not
/// finite.
pub trait Cost {
    /// Called once when the run starts, after the configuration was validated, with the
    /// number of positions: takes the settings the cost needs from `config` and checks its
    /// own storage and the configuration it can run with ([`Error::Capacity`],
    /// [`Error::InvalidConfig`]). Accepts anything by default.
    fn configure(&mut self, _config: &Config, _vertices: usize) -> Result<(), Error> {
        Ok(())
    }
    /// Where the kept vertex goes ([`Placement::Optimal`] needs
    /// [`Positions::Write`](crate::Positions::Write) and no error bound). Subset by default.
    fn placement(&self) -> Placement {
        Placement::Subset
    }
    /// What the cost keeps of one fan while the engine walks it.
    type Fan: Copy;
    /// The summary of an empty fan.
    fn empty(&self) -> Self::Fan;
    /// Adds one triangle of the moving vertex's fan: its unit normal (zero if it has no area)
    /// and twice its area.
    fn add(&self, fan: &mut Self::Fan, normal: V3, area2: f32);
    /// Beside [`Cost::add`], the same triangle's two other corners as offsets from the moving
    /// vertex, in winding order (`dx`, then `dy`); in fan order, one triangle's `dy` is the
    /// next one's `dx`. For a cost that reads the fan's neighbours ([`Energy`]'s springs and
    /// new planes). Nothing by default (the call is dropped).
    #[inline]
    fn corner(&self, _fan: &mut Self::Fan, _dx: V3, _dy: V3) {}
    /// The price of one move of the vertex whose fan was summarised.
    fn price(&self, fan: &Self::Fan, m: &Move) -> f32;
    /// The move's own geometric error, squared, in the normalised units of [`Move`]'s positions,
    /// given the price [`Cost::price`] (or the placed price) gave it: what
    /// [`Config::error_limit`](crate::Config::error_limit) is compared with. Zero by default: a
    /// cost that measures no distance (normal variation) is never limited.
    fn error2(&self, _fan: &Self::Fan, _m: &Move, _price: f32) -> f32 {
        0.0
    }
    /// Whether [`Move::turn`] must be computed (one more fan walk per candidate).
    fn needs_turn(&self) -> bool;
    /// Whether [`Cost::add`], [`Cost::corner`] and [`Cost::round`] use what they are given
    /// (the fan's normals, areas and corners). `false` lets the engine skip a cross product
    /// and a 1/√ per triangle of every walk when the feature rule is off too. `true` by
    /// default.
    fn needs_fan(&self) -> bool {
        true
    }
    /// Called at the start of every round with the mean of twice the triangle area over the
    /// current mesh (the scale of its triangles). Nothing by default.
    fn round(&mut self, _mean_area2: f32) {}
    /// Whether the cost keeps state per vertex (stored quadrics). If so the engine, once before
    /// the first keys, hands it every used vertex's planes ([`Cost::plane`]); after each
    /// collapse it calls [`Cost::merge`]. Unless it [`Cost::needs_fan`], such a cost's price
    /// of `x -> y` must depend only on the two vertices' states and positions: without the
    /// feature rule the engine then re-keys a collapse's neighbours by their one changed
    /// price, onto the kept vertex (a storing cost that reads the fan is re-keyed in full).
    fn stores(&self) -> bool {
        false
    }
    /// Adds `weight · (n·x + d)²` to vertex `v`'s state (only if [`Cost::stores`]): the plane
    /// of one of its triangles (weight: twice its area), or a boundary plane. `x` is relative
    /// to `v`'s position (the engine passes planes through `v`, so `d` is zero): a cost may keep
    /// each vertex's state in a frame centred on it, which keeps `f32` sums of nearby planes
    /// free of the cancellation a global origin causes.
    fn plane(&mut self, _v: usize, _n: V3, _d: f32, _weight: f32) {}
    /// Hands a storing cost one triangle of `v`'s fan when the planes are initialised (only
    /// if [`Cost::stores`]), beside [`Cost::plane`]: its three corners as the caller's vertices
    /// in winding order from `v`'s corner (`corners[0]` is `v` itself, or with welded seams
    /// (`seam`, crate feature `seams`) the wedge the triangle has at `v`'s position), and `e1`, `e2` the
    /// other two corners' positions relative to `v` (normalised units). A plane does not say
    /// which vertices span it: a cost that reads per-vertex data besides positions (attribute
    /// gradients, [`AttributeQuadric`]) needs the corners. Nothing by default.
    fn triangle(&mut self, _v: usize, _corners: [usize; 3], _e1: V3, _e2: V3) {}
    /// Adds the plane through one of `v`'s boundary edges, perpendicular to its triangle (Cheng,
    /// Pan and Shi 1998 §3.3); `weight` is the squared edge length, the cost applies its own
    /// factor.
    fn boundary_plane(&mut self, _v: usize, _n: V3, _d: f32, _weight: f32) {}
    /// Vertex `from` (at `p_from`) was collapsed onto `to` (at `p_to`), which is now at `p_new`
    /// (only if [`Cost::stores`]).
    fn merge(&mut self, _from: usize, _to: usize, _p_from: V3, _p_to: V3, _p_new: V3) {}
    /// Whether [`Cost::place`] may ever return a position. `false` (the default) lets the
    /// compiler drop the engine's placement paths from the image of a cost that never moves a
    /// vertex.
    const PLACES: bool = false;
    /// Where the kept vertex goes for this move, if it moves at all (optimal placement); the
    /// engine checks the legality rules there and writes it to the caller's mutable positions.
    /// `None` by default: the kept vertex stays (subset placement).
    fn place(&self, _m: &Move) -> Option<V3> {
        None
    }
    /// What removing a whole part (a connected component) costs, in this cost's units, for
    /// pruning (`Simplifier::with_parts`, crate feature `parts`): `r2` is the part's squared
    /// radius about its centroid and `area2` twice its area, both in normalised units. A part
    /// is removed once it is cheaper than the collapse the queue is about to make. Infinite by
    /// default: a cost that does not say what a part is worth never removes one.
    fn part(&self, _r2: f32, _area2: f32) -> f32 {
        f32::INFINITY
    }
}

/// [`Cost::part`] for the quadric costs: `r2 · area2`, the area-weighted squared distance of
/// every triangle plane of the part to a point within `r` of all of them (its centroid), which
/// is at most what collapsing the whole part to its centroid would cost under a quadric (the
/// sum over its triangles of twice the area times the squared distance of the centroid to the
/// triangle's plane). Area times squared length, as the quadric keys are.
pub(crate) fn quadric_part(r2: f32, area2: f32) -> f32 {
    r2 * area2
}
