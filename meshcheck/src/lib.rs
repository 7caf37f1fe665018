//! The one validity checker of tinydecimate: the library's tests (`tests/common`), the fuzz
//! targets (`fuzz/src`) and host-sim (`check`, `simplify`, `bench`) all call this crate. It is
//! written independently of the library on purpose: std collections and f64 geometry, no code
//! shared with `src/`.
//!
//! [`analyse`] counts the topology and the defects of one mesh; [`check`] (or [`check_with`])
//! says whether an output is a valid simplification of an input with the same vertex numbering,
//! as a [`Verdict`] that lists every [`Defect`].
//!
//! # Definitions
//!
//! * A triangle is **out of range** if an index is `>= positions.len()`, **degenerate** (a
//!   repeated index) if two of its indices are equal, a **duplicate** if an earlier
//!   non-degenerate triangle has the same vertex set (in any order or winding). Out-of-range and
//!   degenerate triangles take no part in the edge-based counts below; duplicates do.
//! * Edges are undirected vertex pairs of the remaining ("good") triangles. A **boundary edge**
//!   has exactly one triangle, a **non-manifold edge** more than two. An **inconsistent edge**
//!   has two triangles that traverse it in the same direction.
//! * **Boundary loops** are the cycle rank of the graph of boundary edges, `E_b - V_b + C_b`
//!   (`C_b` its connected components): the number of loops when every boundary vertex has two
//!   boundary edges, and two loops touching at a pinched boundary vertex still count as two.
//! * A **pinched** (non-manifold) vertex has good triangles that form more than one fan
//!   connected through edges at that vertex.
//! * A **folded pair** is two triangles with different vertex sets on a common edge whose unit
//!   normals (f64) have a dot product below [`FOLD_DOT`]. Every pair around a non-manifold edge
//!   is tested. Triangles without a normal (zero area) are never folded.
//! * A **zero-area** triangle is a good triangle whose f64 cross product has no positive finite
//!   length.
//! * `euler` is `V - E + F`: V the vertices of in-range triangles, E the edges, F the good
//!   triangles. **Components** are groups of in-range triangles connected through shared
//!   vertices.
//!
//! # What [`check`] compares
//!
//! The input is first *cleaned* as the library cleans it: degenerate triangles and later
//! duplicates dropped. Then:
//!
//! * always a defect: an out-of-range, degenerate or duplicate output triangle; an output
//!   vertex that the cleaned input does not use (or, with separate position arrays, whose
//!   position changed); a non-manifold edge, pinched vertex, folded pair or zero-area
//!   triangle of the output that the input did not have (compared as sets: an input defect may
//!   stay, a new one may not); a changed number of components;
//! * when the cleaned input has no non-manifold edge (the library's promise: "keeps a closed
//!   manifold closed, keeps the Euler characteristic and the number of boundary loops"): a
//!   changed Euler characteristic, a changed number of boundary loops, a closed input that is
//!   no longer closed, and a **crack**: an output boundary edge with an end that was not a
//!   boundary vertex of the input (boundaries only shrink along themselves; with
//!   [`Options::welded`] both meshes are compared welded by position, so a seam pulled apart
//!   is a crack).

use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt;
use std::hash::{BuildHasherDefault, Hasher};

/// Two triangles sharing an edge are folded when their unit normals' dot product is below this
/// (as `legality::FOLD_DOT` in the library).
pub const FOLD_DOT: f64 = -0.9;

/// A triangle as three vertex indices.
pub type Tri = [u32; 3];

/// An undirected edge, smaller index first.
pub type Edge = (u32, u32);

/// A mesh: positions and triangles indexing them.
#[derive(Clone, Copy, Debug)]
pub struct MeshRef<'a> {
    pub positions: &'a [[f32; 3]],
    pub triangles: &'a [Tri],
}

/// A second view of the geometry for fold and zero-area tests: a fold (or zero area) counts
/// only if it holds in the true positions *and* in this view, with `margin` subtracted from
/// [`FOLD_DOT`] and both triangles' quality above `min_quality` in the view. The fuzz targets
/// pass the engine's own normalised f32 view here, so that detail finer than f32 resolution at
/// the mesh's scale is not counted as a defect the engine failed to see.
#[derive(Clone, Copy, Debug)]
pub struct View<'a> {
    pub positions: &'a [[f32; 3]],
    pub margin: f64,
    pub min_quality: f64,
}

/// Options of [`check_with`] and [`analyse_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Options<'a> {
    /// See [`View`]. Used for both meshes; only meaningful when they share their positions.
    pub view: Option<View<'a>>,
    /// With separate position arrays: a kept vertex may have moved (optimal placement of
    /// stored quadrics writes new positions). Every other rule still applies, on the output's
    /// own positions.
    pub allow_moved: bool,
    /// Seams welded (`tinydecimate::seam`): vertices at identical positions are one vertex
    /// with several wedges. Both meshes are welded by position ([`weld`]) before every test,
    /// so a crack (a seam opened by the simplification) shows as [`Defect::Crack`] and
    /// changed boundary loops; and the input wedges of positions the output still uses but
    /// the output does not are counted ([`Verdict::lost_wedges`]).
    pub welded: bool,
    /// Parts may vanish (`tinydecimate` with `Simplifier::with_parts`): a component of the
    /// cleaned input none of whose vertices the output uses was removed on purpose and is
    /// counted ([`Verdict::parts_removed`]); every test then compares the output with the
    /// input less those components. A component the output still touches is compared in
    /// full, so one cut in part is refused as before (its new boundary, its changed Euler
    /// characteristic or loops). With `welded`, components of positions.
    pub parts: bool,
}

/// Topology and defect counts of a mesh. See the crate documentation for the definitions.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Topology {
    /// All triangles, whatever their state.
    pub triangles: usize,
    /// Vertices used by at least one in-range triangle.
    pub referenced_vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges with exactly one triangle.
    pub boundary_edges: usize,
    /// Cycle rank of the boundary-edge graph.
    pub boundary_loops: usize,
    /// Edges with more than two triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose triangles form more than one edge-connected fan.
    pub non_manifold_vertices: usize,
    /// Triangles with a repeated index.
    pub degenerate_triangles: usize,
    /// Triangles with the same vertex set as an earlier one.
    pub duplicate_triangles: usize,
    /// Triangles with an index past the last position.
    pub out_of_range_triangles: usize,
    /// Two-triangle edges traversed in the same direction by both.
    pub inconsistent_edges: usize,
    /// Edge-adjacent triangle pairs with normals' dot below [`FOLD_DOT`].
    pub folded_pairs: usize,
    /// Good triangles without area.
    pub zero_area_triangles: usize,
    /// V - E + F.
    pub euler: i64,
    /// Vertex-connected components of triangles.
    pub components: usize,
}

/// [`Topology`] and the sets behind its counts.
#[derive(Clone, Debug, Default)]
pub struct Analysis {
    pub topology: Topology,
    /// Vertices of good triangles.
    pub vertices: BTreeSet<u32>,
    /// Vertices of boundary edges.
    pub boundary_vertices: BTreeSet<u32>,
    /// Boundary edges, sorted.
    pub boundary_edges: Vec<Edge>,
    pub non_manifold_edges: BTreeSet<Edge>,
    pub pinched_vertices: BTreeSet<u32>,
    pub inconsistent_edges: BTreeSet<Edge>,
    /// Folded pairs as (smaller, larger) sorted vertex triples (in the view too, if any).
    pub folded: BTreeSet<(Tri, Tri)>,
    /// Folded pairs in the true positions (whatever the view says).
    pub folded_true: BTreeSet<(Tri, Tri)>,
    /// Folded pairs in the view (whatever the true positions say); `folded_true` without one.
    pub folded_view: BTreeSet<(Tri, Tri)>,
    /// Zero-area good triangles as sorted vertex triples (in the view too, if any).
    pub zero_area: BTreeSet<Tri>,
    /// Indices (in the triangle list) of out-of-range, degenerate and duplicate triangles.
    pub out_of_range: Vec<usize>,
    pub degenerate: Vec<usize>,
    pub duplicates: Vec<usize>,
}

impl Analysis {
    /// The vertices the library locks: on a non-manifold or inconsistent edge, or pinched.
    pub fn locked_vertices(&self) -> BTreeSet<u32> {
        let mut s: BTreeSet<u32> = self.pinched_vertices.clone();
        for &(a, b) in self
            .non_manifold_edges
            .iter()
            .chain(&self.inconsistent_edges)
        {
            s.insert(a);
            s.insert(b);
        }
        s
    }
}

/// One reason why an output is not a valid simplification of its input.
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Defect {
    /// Output triangle (by position in the output) with an index past the positions.
    OutOfRange {
        triangle: usize,
    },
    /// Output triangle with a repeated index.
    RepeatedIndex {
        triangle: usize,
    },
    /// Output triangle with the vertex set of an earlier output triangle.
    Duplicate {
        triangle: usize,
    },
    /// Output vertex that no (cleaned) input triangle uses.
    NewVertex {
        vertex: u32,
    },
    /// Output vertex whose position differs from the input's.
    MovedVertex {
        vertex: u32,
    },
    NewNonManifoldEdge {
        edge: Edge,
    },
    NewPinchedVertex {
        vertex: u32,
    },
    NewFold {
        pair: (Tri, Tri),
    },
    /// A zero-area triangle (sorted vertices) the input did not have.
    NewZeroArea {
        triangle: Tri,
    },
    /// More double-sided twins in the output than in the input.
    NewTwins {
        count: usize,
    },
    /// An output boundary edge with an end that was not on the input's boundary: the
    /// surface opened there (with welded seams, compared by position: a seam pulled apart).
    Crack {
        edge: Edge,
        /// The end that was inside the input's surface (the smaller if both were).
        inner: u32,
    },
    /// A closed input whose output has boundary edges.
    Opened {
        boundary_edges: usize,
    },
    BoundaryLoops {
        input: usize,
        output: usize,
    },
    Euler {
        input: i64,
        output: i64,
    },
    Components {
        input: usize,
        output: usize,
    },
}

impl fmt::Display for Defect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Defect::OutOfRange { triangle } => write!(f, "triangle {triangle}: index out of range"),
            Defect::RepeatedIndex { triangle } => write!(f, "triangle {triangle}: repeated index"),
            Defect::Duplicate { triangle } => write!(f, "triangle {triangle}: duplicate"),
            Defect::NewVertex { vertex } => write!(f, "vertex {vertex}: not used by the input"),
            Defect::MovedVertex { vertex } => write!(f, "vertex {vertex}: position changed"),
            Defect::NewNonManifoldEdge { edge } => {
                write!(f, "edge {}-{}: new non-manifold edge", edge.0, edge.1)
            }
            Defect::NewPinchedVertex { vertex } => write!(f, "vertex {vertex}: new pinch"),
            Defect::NewFold { pair } => write!(f, "new folded pair {:?} / {:?}", pair.0, pair.1),
            Defect::NewZeroArea { triangle } => write!(f, "new zero-area triangle {triangle:?}"),
            Defect::NewTwins { count } => {
                write!(f, "{count} double-sided twins more than the input had")
            }
            Defect::Crack { edge, inner } => write!(
                f,
                "crack at edge {}-{}: a boundary edge where the input had surface (vertex \
                 {inner} was not on the input's boundary)",
                edge.0, edge.1
            ),
            Defect::Opened { boundary_edges } => {
                write!(f, "closed input opened: {boundary_edges} boundary edges")
            }
            Defect::BoundaryLoops { input, output } => {
                write!(f, "boundary loops {input} -> {output}")
            }
            Defect::Euler { input, output } => {
                write!(f, "Euler characteristic {input} -> {output}")
            }
            Defect::Components { input, output } => write!(f, "components {input} -> {output}"),
        }
    }
}

/// Whether an output mesh is a valid simplification of an input mesh: counts per kind of
/// defect, the topology figures compared, and every defect in [`Verdict::defects`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Verdict {
    /// Non-manifold edges of the output that the input did not have.
    pub new_non_manifold_edges: usize,
    /// Pinched vertices of the output that were not pinched in the input.
    pub new_pinched_vertices: usize,
    /// Duplicate triangles in the output.
    pub duplicate_triangles: usize,
    /// Degenerate (repeated-index) triangles in the output.
    pub degenerate_triangles: usize,
    /// Folded pairs of the output that are not folded pairs of the input (compared as vertex
    /// sets of the two triangles).
    pub new_folded_pairs: usize,
    /// Zero-area triangles of the output that are not zero-area triangles of the input.
    pub new_zero_area_triangles: usize,
    /// Output triangles with an index past the end of the output's positions.
    pub out_of_range_triangles: usize,
    /// Output vertices the input does not use, or whose position changed.
    pub new_vertices: usize,
    /// Output boundary vertices that were interior (compared only with a clean input).
    pub new_boundary_vertices: usize,
    /// Output boundary edges with an end among those vertices: cracks, each a
    /// [`Defect::Crack`].
    pub cracks: usize,
    /// With welded seams: input wedges of kept positions that the output does not use
    /// (information, not a defect: a face of a flat-shaded model collapsed away takes its own
    /// wedges with it).
    pub lost_wedges: usize,
    /// With [`Options::parts`]: components of the cleaned input that the output does not
    /// touch at all (removed whole, not a defect).
    pub parts_removed: usize,
    /// Twins (the back of a double-sided triangle: an earlier triangle turned over) in the input
    /// and in the output. The other counts are taken over the fronts alone.
    pub twins: (usize, usize),
    /// Boundary loops of the cleaned input and of the output.
    pub boundary_loops: (usize, usize),
    /// Euler characteristic of the cleaned input and of the output.
    pub euler: (i64, i64),
    /// Components of the cleaned input and of the output.
    pub components: (usize, usize),
    /// Whether Euler characteristic, boundary loops and closedness were compared (the cleaned
    /// input has no non-manifold edge).
    pub topology_compared: bool,
    /// Every defect; empty iff valid.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub defects: Vec<Defect>,
}

impl Verdict {
    /// Whether the boundary-loop count is unchanged (or not compared).
    pub fn boundary_loops_unchanged(&self) -> bool {
        !self.topology_compared || self.boundary_loops.0 == self.boundary_loops.1
    }

    /// Whether the Euler characteristic is unchanged (or not compared).
    pub fn euler_unchanged(&self) -> bool {
        !self.topology_compared || self.euler.0 == self.euler.1
    }

    /// No defect at all.
    pub fn is_valid(&self) -> bool {
        self.defects.is_empty()
    }

    /// Panics with the defects (at most 20 listed) unless valid; `what` names the case.
    #[track_caller]
    pub fn assert_valid(&self, what: &str) {
        if !self.is_valid() {
            panic!("{what}: not a valid simplification\n{}", self.describe(20));
        }
    }

    /// The defects, one a line, at most `per_kind` of each kind (in the order each kind first
    /// occurs), so that a few of one kind do not hide another.
    pub fn describe_by_kind(&self, per_kind: usize) -> String {
        let mut kinds: Vec<(std::mem::Discriminant<Defect>, Vec<&Defect>)> = Vec::new();
        for d in &self.defects {
            let k = std::mem::discriminant(d);
            match kinds.iter_mut().find(|(x, _)| *x == k) {
                Some((_, v)) => v.push(d),
                None => kinds.push((k, vec![d])),
            }
        }
        let mut s = String::new();
        for (_, ds) in kinds {
            for d in ds.iter().take(per_kind) {
                s.push_str(&format!("  {d}\n"));
            }
            if ds.len() > per_kind {
                s.push_str(&format!(
                    "  ... {} more of that kind\n",
                    ds.len() - per_kind
                ));
            }
        }
        s
    }

    /// The defects, one a line, at most `max` of them.
    pub fn describe(&self, max: usize) -> String {
        let mut s = String::new();
        for d in self.defects.iter().take(max) {
            s.push_str(&format!("  {d}\n"));
        }
        if self.defects.len() > max {
            s.push_str(&format!("  ... {} more\n", self.defects.len() - max));
        }
        s
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self;
        let mark = |ok: bool| if ok { "ok" } else { "FAIL" };
        let counts = [
            ("new non-manifold edges", v.new_non_manifold_edges),
            ("new pinched vertices", v.new_pinched_vertices),
            ("duplicate triangles", v.duplicate_triangles),
            ("degenerate triangles", v.degenerate_triangles),
            ("new folded pairs", v.new_folded_pairs),
            ("new zero-area triangles", v.new_zero_area_triangles),
            ("out-of-range triangles", v.out_of_range_triangles),
            ("new or moved vertices", v.new_vertices),
            ("new boundary vertices", v.new_boundary_vertices),
            ("cracks (boundary edges)", v.cracks),
        ];
        for (name, n) in counts {
            writeln!(f, "  {name:<24} {n:<6} {}", mark(n == 0))?;
        }
        if v.twins != (0, 0) {
            writeln!(
                f,
                "  double-sided twins       {} -> {}  (backs of the fronts above, checked with them)",
                v.twins.0, v.twins.1
            )?;
        }
        if v.lost_wedges > 0 {
            writeln!(
                f,
                "  wedges gone with faces   {}      (welded seams: their regions collapsed away)",
                v.lost_wedges
            )?;
        }
        if v.parts_removed > 0 {
            writeln!(
                f,
                "  parts removed whole      {}      (compared: the input less those parts)",
                v.parts_removed
            )?;
        }
        let note = if v.topology_compared {
            ""
        } else {
            " (not compared: non-manifold input)"
        };
        writeln!(
            f,
            "  boundary loops           {} -> {} {}{note}",
            v.boundary_loops.0,
            v.boundary_loops.1,
            mark(v.boundary_loops_unchanged())
        )?;
        writeln!(
            f,
            "  euler characteristic     {} -> {} {}{note}",
            v.euler.0,
            v.euler.1,
            mark(v.euler_unchanged())
        )?;
        writeln!(
            f,
            "  components               {} -> {} {}",
            v.components.0,
            v.components.1,
            mark(v.components.0 == v.components.1)
        )?;
        if !v.is_valid() {
            write!(f, "{}", v.describe_by_kind(3))?;
        }
        write!(f, "  => {}", if v.is_valid() { "VALID" } else { "INVALID" })
    }
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self;
        writeln!(f, "  triangles              {}", t.triangles)?;
        writeln!(f, "  referenced vertices    {}", t.referenced_vertices)?;
        writeln!(f, "  edges                  {}", t.edges)?;
        writeln!(
            f,
            "  boundary edges         {} in {} loop(s)",
            t.boundary_edges, t.boundary_loops
        )?;
        writeln!(f, "  non-manifold edges     {}", t.non_manifold_edges)?;
        writeln!(f, "  non-manifold vertices  {}", t.non_manifold_vertices)?;
        writeln!(f, "  degenerate triangles   {}", t.degenerate_triangles)?;
        writeln!(f, "  duplicate triangles    {}", t.duplicate_triangles)?;
        writeln!(f, "  out-of-range triangles {}", t.out_of_range_triangles)?;
        writeln!(f, "  inconsistent edges     {}", t.inconsistent_edges)?;
        writeln!(f, "  folded pairs           {}", t.folded_pairs)?;
        writeln!(f, "  zero-area triangles    {}", t.zero_area_triangles)?;
        writeln!(f, "  euler (V-E+F)          {}", t.euler)?;
        write!(f, "  components             {}", t.components)
    }
}

/// The hash of the checker's maps and sets (FxHash's multiply-rotate, with the high half
/// folded into the low on finishing): its keys are vertex indices and position bits, not
/// attacker-chosen, and the default SipHash took a sixth of `tinydecimate simplify`'s time on a
/// 70 k-triangle scan.
#[derive(Clone, Copy, Default)]
struct Fx(u64);

impl Hasher for Fx {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.write_u64(u64::from_le_bytes(w));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn finish(&self) -> u64 {
        self.0 ^ (self.0 >> 32)
    }
}

type FxBuild = BuildHasherDefault<Fx>;

/// Marks of the indices `of` yields, for `n` indices (indices past `n` are not marked).
fn marks(n: usize, of: impl IntoIterator<Item = u32>) -> Vec<bool> {
    let mut m = vec![false; n];
    for i in of {
        if let Some(x) = m.get_mut(i as usize) {
            *x = true;
        }
    }
    m
}

/// The marked indices, as a set.
fn marked(m: &[bool]) -> BTreeSet<u32> {
    (0..m.len() as u32).filter(|&i| m[i as usize]).collect()
}

/// Sorted vertex triple of a triangle.
pub fn sorted(t: Tri) -> Tri {
    let mut k = t;
    k.sort_unstable();
    k
}

/// Minimal union-find.
struct Dsu(Vec<u32>);

impl Dsu {
    fn new(n: usize) -> Self {
        Dsu((0..n as u32).collect())
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) -> bool {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
        a != b
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn dot(u: [f64; 3], v: [f64; 3]) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

fn corners(pos: &[[f32; 3]], t: Tri) -> [[f64; 3]; 3] {
    t.map(|i| pos[i as usize].map(f64::from))
}

/// Unit normal of a triangle (f64), `None` without a positive finite area.
pub fn unit_normal(pos: &[[f32; 3]], t: Tri) -> Option<[f64; 3]> {
    let p = corners(pos, t);
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let len = dot(n, n).sqrt();
    (len > 0.0 && len.is_finite()).then(|| n.map(|c| c / len))
}

/// Quality `4√3·area / Σ edge²` (1 for an equilateral triangle, 0 without area), f64.
pub fn quality(pos: &[[f32; 3]], t: Tri) -> f64 {
    let p = corners(pos, t);
    let (u, v, w) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[2], p[1]));
    let n = cross(u, v);
    let s = dot(u, u) + dot(v, v) + dot(w, w);
    if s > 0.0 && s.is_finite() {
        2.0 * 3f64.sqrt() * dot(n, n).sqrt() / s
    } else {
        0.0
    }
}

/// Angle in degrees between two triangles' unit normals (`None` if either has no area).
pub fn normal_angle_deg(pos: &[[f32; 3]], t: Tri, u: Tri) -> Option<f64> {
    let (a, b) = (unit_normal(pos, t)?, unit_normal(pos, u)?);
    Some(dot(a, b).clamp(-1.0, 1.0).acos().to_degrees())
}

/// The triangles as the library keeps them: repeated-index triangles and later duplicates
/// (same vertex set) dropped, but for the first copy turned over (a double-sided triangle's
/// back, see [`split_twins`]); out-of-range triangles dropped too.
pub fn clean(positions: &[[f32; 3]], triangles: &[Tri]) -> Vec<Tri> {
    let good: Vec<Tri> = triangles
        .iter()
        .copied()
        .filter(|t| {
            t.iter().all(|&i| (i as usize) < positions.len())
                && t[0] != t[1]
                && t[1] != t[2]
                && t[0] != t[2]
        })
        .collect();
    let (_, _, fronts) = split_twins(&good);
    let mut front = vec![false; good.len()];
    for i in fronts {
        front[i] = true;
    }
    let mut seen = HashSet::with_capacity_and_hasher(good.len(), FxBuild::default());
    good.iter()
        .enumerate()
        .filter(|(i, t)| !front[*i] || seen.insert(sorted(**t)))
        .map(|(_, t)| *t)
        .collect()
}

/// Counts everything in [`Topology`] and collects the sets of [`Analysis`].
pub fn analyse(positions: &[[f32; 3]], triangles: &[Tri]) -> Analysis {
    analyse_with(positions, triangles, &Options::default())
}

/// [`analyse`] with [`Options`].
pub fn analyse_with(positions: &[[f32; 3]], triangles: &[Tri], opts: &Options) -> Analysis {
    let nv = positions.len();
    let mut an = Analysis::default();
    let topo = &mut an.topology;
    topo.triangles = triangles.len();
    // Triangles taking part in edge counts: in range and not degenerate.
    let mut good: Vec<Tri> = Vec::with_capacity(triangles.len());
    let mut referenced = vec![false; nv];
    let mut vertex_sets = HashSet::with_capacity_and_hasher(triangles.len(), FxBuild::default());
    let mut in_good = vec![false; nv];
    let mut comp = Dsu::new(nv);
    for (i, &t) in triangles.iter().enumerate() {
        if t.iter().any(|&v| v as usize >= nv) {
            an.out_of_range.push(i);
            continue;
        }
        for &v in &t {
            referenced[v as usize] = true;
        }
        comp.union(t[0], t[1]);
        comp.union(t[1], t[2]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            an.degenerate.push(i);
            continue;
        }
        if !vertex_sets.insert(sorted(t)) {
            an.duplicates.push(i);
        }
        for &v in &t {
            in_good[v as usize] = true;
        }
        good.push(t);
    }
    an.vertices = marked(&in_good);
    topo.out_of_range_triangles = an.out_of_range.len();
    topo.degenerate_triangles = an.degenerate.len();
    topo.duplicate_triangles = an.duplicates.len();
    topo.referenced_vertices = referenced.iter().filter(|&&r| r).count();
    topo.components = (0..nv as u32)
        .filter(|&v| referenced[v as usize] && comp.find(v) == v)
        .count();

    // Normals in the true positions and, if given, in the view.
    let normals: Vec<Option<[f64; 3]>> = good.iter().map(|&t| unit_normal(positions, t)).collect();
    let view = opts.view;
    let view_normals: Vec<Option<[f64; 3]>> = match view {
        Some(v) => good
            .iter()
            .map(|&t| {
                if quality(v.positions, t) > v.min_quality {
                    unit_normal(v.positions, t)
                } else {
                    None
                }
            })
            .collect(),
        None => Vec::new(),
    };
    for (i, &t) in good.iter().enumerate() {
        let zero_in_view = match view {
            Some(v) => unit_normal(v.positions, t).is_none(),
            None => true,
        };
        if normals[i].is_none() && zero_in_view {
            an.zero_area.insert(sorted(t));
            topo.zero_area_triangles += 1;
        }
    }

    // Half-edges (lo, hi, triangle, forward), sorted so each edge's triangles are adjacent.
    let mut half: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(good.len() * 3);
    for (ti, t) in good.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), ti as u32, a < b));
        }
    }
    half.sort_unstable();
    let mut boundary_graph: Vec<Edge> = Vec::new();
    for group in half.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        topo.edges += 1;
        let edge = (group[0].0, group[0].1);
        match group.len() {
            1 => {
                topo.boundary_edges += 1;
                boundary_graph.push(edge);
                an.boundary_edges.push(edge);
            }
            2 => {
                if group[0].3 == group[1].3 {
                    an.inconsistent_edges.insert(edge);
                }
            }
            _ => {
                an.non_manifold_edges.insert(edge);
            }
        }
        for (i, x) in group.iter().enumerate() {
            for y in &group[i + 1..] {
                let (tx, ty) = (good[x.2 as usize], good[y.2 as usize]);
                let (kx, ky) = (sorted(tx), sorted(ty));
                if kx == ky {
                    continue; // a duplicate, counted as such
                }
                let pair = (kx.min(ky), kx.max(ky));
                let folded =
                    |n: &[Option<[f64; 3]>], limit: f64| match (n[x.2 as usize], n[y.2 as usize]) {
                        (Some(a), Some(b)) => dot(a, b) < limit,
                        _ => false,
                    };
                let in_true = folded(&normals, FOLD_DOT);
                let in_view = match view {
                    Some(v) => folded(&view_normals, FOLD_DOT - v.margin),
                    None => in_true,
                };
                if in_true {
                    an.folded_true.insert(pair);
                }
                if in_view {
                    an.folded_view.insert(pair);
                }
                if in_true && in_view {
                    an.folded.insert(pair);
                }
            }
        }
    }
    an.boundary_vertices = marked(&marks(
        nv,
        an.boundary_edges.iter().flat_map(|&(a, b)| [a, b]),
    ));
    topo.non_manifold_edges = an.non_manifold_edges.len();
    topo.inconsistent_edges = an.inconsistent_edges.len();
    topo.folded_pairs = an.folded.len();

    // Boundary loops: cycle rank E - V + C of the boundary-edge graph = E - merges.
    let mut bdsu = Dsu::new(nv);
    let merges = boundary_graph
        .iter()
        .filter(|&&(a, b)| bdsu.union(a, b))
        .count();
    topo.boundary_loops = boundary_graph.len() - merges;

    an.pinched_vertices = pinched_vertices(nv, &good);
    topo.non_manifold_vertices = an.pinched_vertices.len();
    topo.euler = topo.referenced_vertices as i64 - topo.edges as i64 + good.len() as i64;
    an
}

/// Vertices whose incident triangles form more than one fan connected through edges at the
/// vertex.
fn pinched_vertices(nv: usize, good: &[Tri]) -> BTreeSet<u32> {
    // Vertex -> incident triangles, CSR.
    let mut start = vec![0u32; nv + 1];
    for t in good {
        for &i in t {
            start[i as usize + 1] += 1;
        }
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut inc = vec![0u32; good.len() * 3];
    for (ti, t) in good.iter().enumerate() {
        for &i in t {
            inc[fill[i as usize] as usize] = ti as u32;
            fill[i as usize] += 1;
        }
    }
    let mut pinched = BTreeSet::new();
    let mut first_at: Vec<(u32, u32)> = Vec::new();
    for v in 0..nv {
        let tris = &inc[start[v] as usize..start[v + 1] as usize];
        if tris.len() < 2 {
            continue;
        }
        // Local union-find over the fan; triangles sharing another vertex w share edge v-w.
        let mut dsu = Dsu::new(tris.len());
        first_at.clear();
        for (li, &ti) in tris.iter().enumerate() {
            for &w in &good[ti as usize] {
                if w as usize != v {
                    first_at.push((w, li as u32));
                }
            }
        }
        first_at.sort_unstable();
        for pair in first_at.windows(2) {
            if pair[0].0 == pair[1].0 {
                dsu.union(pair[0].1, pair[1].1);
            }
        }
        let fans = (0..tris.len() as u32).filter(|&i| dsu.find(i) == i).count();
        if fans > 1 {
            pinched.insert(v as u32);
        }
    }
    pinched
}

/// Whether `output` is a valid simplification of `input`; both index `positions`.
pub fn check(positions: &[[f32; 3]], input: &[Tri], output: &[Tri]) -> Verdict {
    check_with(
        MeshRef {
            positions,
            triangles: input,
        },
        MeshRef {
            positions,
            triangles: output,
        },
        &Options::default(),
    )
}

/// `triangles` with every index renumbered to the first vertex of `positions` at the same
/// position (`-0.0` equal to `0.0`): one vertex per position, as `tinydecimate::seam::weld`
/// numbers them. Out-of-range indices stay.
pub fn weld(positions: &[[f32; 3]], triangles: &[Tri]) -> Vec<Tri> {
    let key = |p: &[f32; 3]| p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
    let mut first = HashMap::with_capacity_and_hasher(positions.len(), FxBuild::default());
    for (i, p) in positions.iter().enumerate() {
        first.entry(key(p)).or_insert(i as u32);
    }
    triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                positions
                    .get(v as usize)
                    .and_then(|p| first.get(&key(p)).copied())
                    .unwrap_or(v)
            })
        })
        .collect()
}

/// [`check`] with separate position arrays (same vertex numbering) and [`Options`].
pub fn check_with(input: MeshRef, output: MeshRef, opts: &Options) -> Verdict {
    if opts.welded {
        // Welded first: a back with its own vertices is a twin by position.
        return check_welded(input, output, opts);
    }
    // Double-sided surfaces: each back (an earlier triangle turned over) is its front's copy,
    // so the fronts are checked as the one-sided surface they are, and the backs counted.
    let (fi, twins_in, _) = split_twins(input.triangles);
    let (fo, twins_out, index) = split_twins(output.triangles);
    if twins_in + twins_out > 0 {
        let mut v = check_with(
            MeshRef {
                positions: input.positions,
                triangles: &fi,
            },
            MeshRef {
                positions: output.positions,
                triangles: &fo,
            },
            opts,
        );
        // Defects name triangles by their place in the whole output.
        for d in &mut v.defects {
            if let Defect::OutOfRange { triangle }
            | Defect::RepeatedIndex { triangle }
            | Defect::Duplicate { triangle } = d
            {
                *triangle = index.get(*triangle).copied().unwrap_or(*triangle);
            }
        }
        if twins_out > twins_in {
            v.defects.push(Defect::NewTwins {
                count: twins_out - twins_in,
            });
        }
        v.twins = (twins_in, twins_out);
        return v;
    }
    check_split(input, output, opts)
}

/// The triangles less the twins (a triangle whose vertex set an earlier one has, turned over,
/// and the first such), how many twins there were, and each kept triangle's place in
/// `triangles`. Repeated copies in either winding stay, to be counted as duplicates.
pub fn split_twins(triangles: &[Tri]) -> (Vec<Tri>, usize, Vec<usize>) {
    // Per vertex set: the first copy's winding, and whether a twin was taken.
    let mut seen: HashMap<Tri, (Tri, bool), FxBuild> =
        HashMap::with_capacity_and_hasher(triangles.len(), FxBuild::default());
    let (mut kept, mut index, mut twins) = (Vec::with_capacity(triangles.len()), Vec::new(), 0);
    for (i, &t) in triangles.iter().enumerate() {
        let rotations = |a: Tri| [a, [a[1], a[2], a[0]], [a[2], a[0], a[1]]];
        let twin = t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && {
            match seen.get_mut(&sorted(t)) {
                Some((first, taken)) if !*taken && !rotations(*first).contains(&t) => {
                    *taken = true;
                    true
                }
                Some(_) => false,
                None => {
                    seen.insert(sorted(t), (t, false));
                    false
                }
            }
        };
        if twin {
            twins += 1;
        } else {
            kept.push(t);
            index.push(i);
        }
    }
    (kept, twins, index)
}

/// [`check_with`] for welded seams: the tests on both meshes welded by position, then the
/// wedges of the kept positions.
fn check_welded(input: MeshRef, output: MeshRef, opts: &Options) -> Verdict {
    let (wi, wo) = (
        weld(input.positions, input.triangles),
        weld(output.positions, output.triangles),
    );
    let split = Options {
        welded: false,
        ..*opts
    };
    let mut v = check_with(
        MeshRef {
            positions: input.positions,
            triangles: &wi,
        },
        MeshRef {
            positions: output.positions,
            triangles: &wo,
        },
        &split,
    );
    let n = input.positions.len().max(output.positions.len());
    let kept = marks(n, wo.iter().flatten().copied());
    let used = marks(n, output.triangles.iter().flatten().copied());
    let is = |m: &[bool], i: u32| m.get(i as usize).copied().unwrap_or(false);
    let mut lost = vec![false; n];
    for (t, w) in input.triangles.iter().zip(&wi) {
        for (&raw, &rep) in t.iter().zip(w) {
            if is(&kept, rep) && !is(&used, raw) {
                if let Some(x) = lost.get_mut(raw as usize) {
                    *x = true;
                }
            }
        }
    }
    let lost: Vec<u32> = (0..n as u32).filter(|&i| lost[i as usize]).collect();
    // Counted, not a defect: a wedge whose whole attribute region was collapsed away (a face
    // of a flat-shaded model, where every face has its own wedges) is lost on purpose, and
    // the output alone cannot tell that from a region whose corners took another wedge.
    v.lost_wedges = lost.len();
    v
}

/// `cleaned` less its components that `output` does not touch, and how many those were.
fn without_absent_parts(nv: usize, cleaned: &[Tri], output: &[Tri]) -> (Vec<Tri>, usize) {
    let mut dsu = Dsu::new(nv);
    for t in cleaned {
        dsu.union(t[0], t[1]);
        dsu.union(t[1], t[2]);
    }
    let mut present = vec![false; nv];
    for &v in output.iter().flatten() {
        if (v as usize) < nv {
            let r = dsu.find(v);
            present[r as usize] = true;
        }
    }
    let mut absent = BTreeSet::new();
    let kept = cleaned
        .iter()
        .copied()
        .filter(|t| {
            let r = dsu.find(t[0]);
            if !present[r as usize] {
                absent.insert(r);
            }
            present[r as usize]
        })
        .collect();
    (kept, absent.len())
}

fn check_split(input: MeshRef, output: MeshRef, opts: &Options) -> Verdict {
    let cleaned = clean(input.positions, input.triangles);
    let (cleaned, parts_removed) = if opts.parts {
        without_absent_parts(input.positions.len(), &cleaned, output.triangles)
    } else {
        (cleaned, 0)
    };
    let cin = analyse_with(input.positions, &cleaned, opts);
    // `clean` and the parts only drop triangles: the same count is the same list, analysed once.
    let raw_owned;
    let raw = if cleaned.len() == input.triangles.len() {
        &cin
    } else {
        raw_owned = analyse_with(input.positions, input.triangles, opts);
        &raw_owned
    };
    let out = analyse_with(output.positions, output.triangles, opts);
    let mut d = Vec::new();

    d.extend(
        out.out_of_range
            .iter()
            .map(|&triangle| Defect::OutOfRange { triangle }),
    );
    d.extend(
        out.degenerate
            .iter()
            .map(|&triangle| Defect::RepeatedIndex { triangle }),
    );
    d.extend(
        out.duplicates
            .iter()
            .map(|&triangle| Defect::Duplicate { triangle }),
    );
    let mut new_vertices = 0;
    for &v in &out.vertices {
        if !cin.vertices.contains(&v) {
            d.push(Defect::NewVertex { vertex: v });
            new_vertices += 1;
        } else if !opts.allow_moved
            && !std::ptr::eq(input.positions, output.positions)
            && input.positions.get(v as usize) != output.positions.get(v as usize)
        {
            d.push(Defect::MovedVertex { vertex: v });
            new_vertices += 1;
        }
    }
    // Input defects (raw and cleaned) may stay; new ones may not.
    let new_nm: Vec<Edge> = out
        .non_manifold_edges
        .difference(&raw.non_manifold_edges)
        .copied()
        .collect();
    d.extend(
        new_nm
            .iter()
            .map(|&edge| Defect::NewNonManifoldEdge { edge }),
    );
    let new_pinched: Vec<u32> = out
        .pinched_vertices
        .iter()
        .filter(|v| !raw.pinched_vertices.contains(v) && !cin.pinched_vertices.contains(v))
        .copied()
        .collect();
    d.extend(
        new_pinched
            .iter()
            .map(|&vertex| Defect::NewPinchedVertex { vertex }),
    );
    // A fold counts only if it is new both in the true geometry and in the view.
    let new_folds: Vec<(Tri, Tri)> = out
        .folded
        .iter()
        .filter(|p| !raw.folded_true.contains(p) && !raw.folded_view.contains(p))
        .copied()
        .collect();
    d.extend(new_folds.iter().map(|&pair| Defect::NewFold { pair }));
    let new_zero: Vec<Tri> = out.zero_area.difference(&raw.zero_area).copied().collect();
    d.extend(
        new_zero
            .iter()
            .map(|&triangle| Defect::NewZeroArea { triangle }),
    );

    let (ti, to) = (&cin.topology, &out.topology);
    if ti.components != to.components {
        d.push(Defect::Components {
            input: ti.components,
            output: to.components,
        });
    }
    let topology_compared = ti.non_manifold_edges == 0;
    let mut new_boundary_vertices = 0;
    let mut cracks = 0;
    if topology_compared {
        if ti.euler != to.euler {
            d.push(Defect::Euler {
                input: ti.euler,
                output: to.euler,
            });
        }
        if ti.boundary_loops != to.boundary_loops {
            d.push(Defect::BoundaryLoops {
                input: ti.boundary_loops,
                output: to.boundary_loops,
            });
        }
        if ti.boundary_edges == 0 && to.boundary_edges != 0 {
            d.push(Defect::Opened {
                boundary_edges: to.boundary_edges,
            });
        }
        new_boundary_vertices = out
            .boundary_vertices
            .difference(&cin.boundary_vertices)
            .count();
        for &edge in &out.boundary_edges {
            let inner = [edge.0, edge.1]
                .into_iter()
                .find(|v| !cin.boundary_vertices.contains(v));
            if let Some(inner) = inner {
                d.push(Defect::Crack { edge, inner });
                cracks += 1;
            }
        }
    }

    Verdict {
        new_non_manifold_edges: new_nm.len(),
        new_pinched_vertices: new_pinched.len(),
        duplicate_triangles: to.duplicate_triangles,
        degenerate_triangles: to.degenerate_triangles,
        new_folded_pairs: new_folds.len(),
        new_zero_area_triangles: new_zero.len(),
        out_of_range_triangles: to.out_of_range_triangles,
        new_vertices,
        new_boundary_vertices,
        cracks,
        lost_wedges: 0,
        parts_removed,
        twins: (0, 0),
        boundary_loops: (ti.boundary_loops, to.boundary_loops),
        euler: (ti.euler, to.euler),
        components: (ti.components, to.components),
        topology_compared,
        defects: d,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n x n grid of unit quads on z = 0.
    fn grid(n: u32) -> (Vec<[f32; 3]>, Vec<Tri>) {
        let mut p = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                p.push([x as f32, y as f32, 0.0]);
            }
        }
        let mut t = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                t.push([v, v + 1, v + n + 2]);
                t.push([v, v + n + 2, v + n + 1]);
            }
        }
        (p, t)
    }

    #[test]
    fn identity_is_valid_and_each_defect_is_named() {
        let (p, t) = grid(3);
        assert!(check(&p, &t, &t).is_valid());

        // Repeated index, duplicate, out of range.
        let mut o = t.clone();
        o.push([0, 0, 1]);
        o.push([1, 5, 0]);
        o.push([0, 1, 99]);
        let v = check(&p, &t, &o);
        assert!(v.defects.contains(&Defect::RepeatedIndex { triangle: 18 }));
        assert!(v.defects.contains(&Defect::Duplicate { triangle: 19 }));
        assert!(v.defects.contains(&Defect::OutOfRange { triangle: 20 }));

        // A vertex the input does not use.
        let mut q = p.clone();
        q.push([9.0, 9.0, 1.0]);
        let mut o = t.clone();
        o[0] = [0, 1, 16];
        let v = check(&q, &t, &o);
        assert!(v.defects.contains(&Defect::NewVertex { vertex: 16 }), "{v}");

        // A zero-area triangle: vertex 5 moved onto the line 0-10.
        let mut z = p.clone();
        z[5] = [1.0, 1.0, 0.0];
        z[10] = [2.0, 2.0, 0.0];
        let o = vec![[0, 5, 10], [0, 1, 5]];
        let v = check(&z, &[[0, 5, 1]], &o);
        assert!(v.new_zero_area_triangles == 1, "{v}");
    }

    #[test]
    fn components_and_boundary_vertices() {
        let (p, t) = grid(3);
        // Dropping every triangle but those of two far corners: two components.
        let o = vec![t[0], t[17]];
        let v = check(&p, &t, &o);
        assert_eq!(v.components, (1, 2));
        assert!(!v.is_valid());
        // Removing one inner quad: its corners become boundary vertices.
        let mut h = t.clone();
        h.drain(8..10);
        let v = check(&p, &t, &h);
        assert_eq!(v.new_boundary_vertices, 4, "{v}");
        // The hole's four edges are the cracks, each named with an end inside the input.
        assert_eq!(v.cracks, 4, "{v}");
        assert!(v.defects.contains(&Defect::Crack {
            edge: (5, 6),
            inner: 5
        }));
        assert!(v.to_string().contains("crack at edge 5-6"), "{v}");
        assert!(v.defects.contains(&Defect::BoundaryLoops {
            input: 1,
            output: 2
        }));
    }

    /// A 2 x 2 grid split on its middle column (vertices 1, 4, 7 copied as 9, 10, 11 for the
    /// right half): the left half's seam shortened alone (4 collapsed into 1) is valid split,
    /// and welded by position a crack along the right half's 1-4-7, named.
    #[test]
    fn a_seam_pulled_apart_is_a_crack_when_welded() {
        let (mut p, t) = grid(2);
        p.extend([p[1], p[4], p[7]]);
        let right = |x: Tri| {
            x.map(|v| match v {
                1 => 9,
                4 => 10,
                7 => 11,
                v => v,
            })
        };
        let input: Vec<Tri> = vec![
            t[0],
            t[1],
            t[4],
            t[5],
            right(t[2]),
            right(t[3]),
            right(t[6]),
            right(t[7]),
        ];
        let mut output = input.clone();
        // 4 -> 1 on the left: [0,1,4] goes, [0,4,3] -> [0,1,3], [3,4,7] -> [3,1,7].
        output.splice(0..4, [[0, 1, 3], [3, 1, 7], t[5]]);
        let opts = |welded| Options {
            welded,
            ..Default::default()
        };
        let verdict = |welded| {
            check_with(
                MeshRef {
                    positions: &p,
                    triangles: &input,
                },
                MeshRef {
                    positions: &p,
                    triangles: &output,
                },
                &opts(welded),
            )
        };
        assert!(verdict(false).is_valid(), "{}", verdict(false));
        let v = verdict(true);
        assert_eq!(v.cracks, 2, "{v}");
        assert!(v.defects.contains(&Defect::Crack {
            edge: (1, 4),
            inner: 4
        }));
        assert!(v.defects.contains(&Defect::Crack {
            edge: (4, 7),
            inner: 4
        }));
    }

    /// With `parts`, a component the output does not touch is allowed and counted; one cut in
    /// part, a new boundary on a kept part, or a defect elsewhere is still refused.
    #[test]
    fn parts_gone_whole_are_allowed_and_cut_ones_refused() {
        // A closed octahedron (vertices 0-5) and a 3 x 3 grid beside it (vertices 6-21).
        let mut p: Vec<[f32; 3]> = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let mut t: Vec<Tri> = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let (gp, gt) = grid(3);
        p.extend(gp.iter().map(|q| [q[0] + 5.0, q[1], q[2]]));
        t.extend(gt.iter().map(|x| x.map(|v| v + 6)));
        let opts = Options {
            parts: true,
            ..Default::default()
        };
        let verdict = |o: &[Tri]| {
            check_with(
                MeshRef {
                    positions: &p,
                    triangles: &t,
                },
                MeshRef {
                    positions: &p,
                    triangles: o,
                },
                &opts,
            )
        };
        // The octahedron gone whole: valid, one part removed; without the option a defect.
        let grid_only = t[8..].to_vec();
        let v = verdict(&grid_only);
        assert!(v.is_valid(), "{v}");
        assert_eq!((v.parts_removed, v.components), (1, (1, 1)));
        assert!(!check(&p, &t, &grid_only).is_valid());
        // The octahedron cut in part (one face left open): refused.
        let cut: Vec<Tri> = t[1..].to_vec();
        let v = verdict(&cut);
        assert_eq!(v.parts_removed, 0);
        assert_eq!(v.new_boundary_vertices, 3, "{v}");
        assert!(v.defects.contains(&Defect::BoundaryLoops {
            input: 1,
            output: 2
        }));
        // Cut down to one triangle of the octahedron: still refused.
        let mut rest = grid_only.clone();
        rest.push(t[0]);
        assert!(!verdict(&rest).is_valid());
        // The octahedron gone and a hole in the grid: the new boundary is refused.
        let mut holed = grid_only.clone();
        holed.drain(8..10);
        let v = verdict(&holed);
        assert_eq!(v.parts_removed, 1);
        assert!(v.new_boundary_vertices > 0, "{v}");
        assert!(!v.is_valid());
        // Everything gone: both parts removed, nothing else to say.
        let v = verdict(&[]);
        assert_eq!(v.parts_removed, 2);
    }

    #[test]
    fn dirty_input_is_compared_after_cleaning() {
        let (p, t) = grid(2);
        // The input has a repeated-index triangle on an otherwise unused vertex and a
        // duplicate; the library drops both, so the clean output is valid.
        let mut q = p.clone();
        q.push([5.0, 5.0, 0.0]);
        let mut dirty = t.clone();
        dirty.push([9, 9, 0]);
        dirty.push(t[3]);
        let v = check(&q, &dirty, &t);
        assert!(v.is_valid(), "{v}");
        assert!(v.topology_compared);
    }

    #[test]
    fn folds_new_in_the_view_only_do_not_count() {
        let (p, t) = grid(1);
        // Flip vertex 3 across: triangles 0 and 1 fold in the true positions.
        let mut f = p.clone();
        f[3] = [1.5, -0.5, 0.0];
        let inp = [MeshRef {
            positions: &p,
            triangles: &t,
        }];
        let out = MeshRef {
            positions: &f,
            triangles: &t,
        };
        let v = check_with(inp[0], out, &Options::default());
        assert_eq!(v.new_folded_pairs, 1, "{v}");
        assert!(v.defects.contains(&Defect::MovedVertex { vertex: 3 }));
        let a = analyse(&f, &t);
        assert_eq!(a.topology.folded_pairs, 1);
        // Seen through a view in which nothing is folded, it does not count.
        let view = View {
            positions: &p,
            margin: 0.0,
            min_quality: 0.0,
        };
        let a = analyse_with(
            &f,
            &t,
            &Options {
                view: Some(view),
                allow_moved: false,
                welded: false,
                parts: false,
            },
        );
        assert_eq!((a.folded.len(), a.folded_true.len()), (0, 1));
    }
}
