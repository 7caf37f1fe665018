//! Collapse costs: how much moving one vertex onto a neighbour changes the surface.
//!
//! The engine evaluates a collapse `from -> to` triangle by triangle (it needs each surviving
//! triangle's old and new normal for the legality rules anyway) and hands every surviving
//! triangle to [`Cost::triangle`]; triangles on the collapsed edge vanish and count 0
//! (seed 004 §2.1). [`Cost::total`] then turns the sum into the collapse's priority. A new cost
//! is a new implementation of this trait, passed to
//! [`Workspace::start_with_cost`](crate::Workspace::start_with_cost); the engine does not change.
//!
//! All lengths are in the engine's normalised units (the input's bounding box mapped to about
//! `[-1, 1]³`), so costs do not depend on the scale of the input.

/// One triangle of the moving vertex that survives the collapse.
#[derive(Clone, Copy, Debug)]
pub struct TriangleChange {
    /// Unit normal before the collapse (zero for a zero-area triangle).
    pub old_normal: [f32; 3],
    /// Unit normal after the collapse.
    pub new_normal: [f32; 3],
    /// Twice the triangle's area before the collapse.
    pub old_area2: f32,
    /// How far the moving vertex moves (`to - from`).
    pub moved: [f32; 3],
}

/// The collapsed edge.
#[derive(Clone, Copy, Debug)]
pub struct EdgeChange {
    /// Squared length of the edge.
    pub length2: f32,
    /// For a boundary vertex moving along its boundary: squared distance from it to the new
    /// boundary edge, i.e. how far the boundary retreats. Zero otherwise.
    pub boundary_retreat2: f32,
}

/// A collapse cost. Lower is better; the engine never performs a collapse whose total is not
/// finite.
pub trait Cost {
    /// Contribution of one surviving triangle.
    fn triangle(&self, change: &TriangleChange) -> f32;
    /// The collapse's cost from the sum of the triangle terms.
    fn total(&self, sum: f32, edge: &EdgeChange) -> f32;
}

/// The paper's normal variation W (seed 004 §2, eq. 1-2, Algorithm 1): the sum over the moving
/// vertex's triangles of ‖N_new − N_old‖², with no trigonometry.
///
/// Two refinements, both reducing to the paper's W on an interior vertex when switched off:
///
/// * `length_weighted`: multiply by the squared edge length. W measures how far normals turn,
///   not how far the surface moves; as a *global* priority alone it prefers long collapses
///   across flat or cylindrical regions and piles edges onto hubs. Displacement is about
///   length × normal change, so W·ℓ² ranks collapses by a squared distance.
/// * `boundary_weight`: a boundary vertex moving along its boundary adds
///   `boundary_weight · retreat² / ℓ²` (scale-free like W; W·ℓ² then gets `boundary_weight ·
///   retreat²`), so open meshes keep their rims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalVariation {
    /// Multiply by the squared edge length (greedy schedule).
    pub length_weighted: bool,
    /// Weight of the boundary retreat.
    pub boundary_weight: f32,
}

impl NormalVariation {
    /// W as in the paper, plus the boundary term: the cost of the `Passes` schedule.
    pub const fn paper(boundary_weight: f32) -> Self {
        NormalVariation {
            length_weighted: false,
            boundary_weight,
        }
    }

    /// W·ℓ² plus the boundary term: the cost of the `Greedy` schedule.
    pub const fn greedy(boundary_weight: f32) -> Self {
        NormalVariation {
            length_weighted: true,
            boundary_weight,
        }
    }
}

impl Cost for NormalVariation {
    #[inline]
    fn triangle(&self, c: &TriangleChange) -> f32 {
        // Eq. 2: ‖U − V‖² = (Ux − Vx)² + (Uy − Vy)² + (Uz − Vz)².
        let d = crate::math::sub(c.new_normal, c.old_normal);
        crate::math::dot(d, d)
    }

    #[inline]
    fn total(&self, sum: f32, e: &EdgeChange) -> f32 {
        if self.length_weighted {
            sum * e.length2 + self.boundary_weight * e.boundary_retreat2
        } else if e.length2 > 0.0 {
            sum + self.boundary_weight * e.boundary_retreat2 / e.length2
        } else {
            sum
        }
    }
}

/// Memoryless quadric error (Lindstrom and Turk's variant of seeds 000/003's quadrics, which
/// needs no per-vertex matrix): the sum over the moving vertex's triangles of the area-weighted
/// squared distance from the new position to the triangle's old plane. Shown here as the
/// second cost that plugs into the same engine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneDistance {
    /// Weight of the boundary retreat, as in [`NormalVariation`].
    pub boundary_weight: f32,
}

impl Cost for PlaneDistance {
    #[inline]
    fn triangle(&self, c: &TriangleChange) -> f32 {
        let d = crate::math::dot(c.old_normal, c.moved);
        d * d * c.old_area2
    }

    #[inline]
    fn total(&self, sum: f32, e: &EdgeChange) -> f32 {
        // retreat² · ℓ² has the units of the triangle terms (squared distance × area).
        sum + self.boundary_weight * e.boundary_retreat2 * e.length2
    }
}
