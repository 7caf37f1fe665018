//! Mesh validity: topology counts of one mesh ([`analyse`]) and whether a simplification is a
//! valid one of its input ([`compare`]).
//!
//! Definitions (they match `/work/shared/meshes/SOURCES.md`):
//!
//! * A triangle is **out of range** if an index is `>= positions.len()`, **degenerate** if two
//!   of its indices are equal, a **duplicate** if an earlier non-degenerate triangle has the
//!   same vertex set. Out-of-range and degenerate triangles take no part in the edge-based
//!   counts below; duplicates do.
//! * Edges are undirected vertex pairs of the remaining triangles. A **boundary edge** has
//!   exactly one triangle, a **non-manifold edge** more than two. An **inconsistent edge** has
//!   two triangles that traverse it in the same direction.
//! * **Boundary loops** are counted as the cycle rank of the graph of boundary edges,
//!   `E_b - V_b + C_b` (C_b its connected components). This is the number of loops when every
//!   boundary vertex has two boundary edges, and it still counts two loops that touch at a
//!   pinched (non-manifold) boundary vertex as two, where walking by vertex could not tell.
//! * A **non-manifold vertex** has incident triangles that form more than one fan connected
//!   through edges at that vertex (a pinch).
//! * A **folded pair** is two triangles sharing an edge whose unit normals (f64) have a dot
//!   product below [`FOLD_DOT`]; zero-area triangles have no normal and are never folded. Every
//!   pair around a non-manifold edge is tested.
//! * `euler` is `V - E + F` with V the referenced vertices, E the edges, F the triangles that
//!   are neither out of range nor degenerate. **Components** are groups of triangles connected
//!   through shared vertices.

use std::collections::HashSet;
use std::fmt;

use serde::Serialize;

use crate::io::MeshData;

/// Two triangles sharing an edge are folded when their unit normals' dot product is below this.
pub const FOLD_DOT: f64 = -0.9;

/// Topology and defect counts of a mesh. See the module documentation for the definitions.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
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
    /// V - E + F.
    pub euler: i64,
    /// Vertex-connected components of triangles.
    pub components: usize,
}

/// Whether an output mesh is a valid simplification of an input mesh.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Validity {
    /// Output non-manifold edges minus input ones, floored at 0.
    pub new_non_manifold_edges: usize,
    /// Duplicate triangles in the output.
    pub duplicate_triangles: usize,
    /// Degenerate triangles in the output.
    pub degenerate_triangles: usize,
    /// Folded pairs of the output that are not folded pairs of the input (compared as vertex
    /// sets of the two triangles).
    pub new_folded_pairs: usize,
    /// Output triangles with an index past the end of the output's positions.
    pub out_of_range_triangles: usize,
    /// Boundary loops of the input and the output.
    pub boundary_loops: (usize, usize),
    /// Euler characteristic of the input and the output.
    pub euler: (i64, i64),
}

impl Validity {
    /// Whether the boundary-loop count is unchanged.
    pub fn boundary_loops_unchanged(&self) -> bool {
        self.boundary_loops.0 == self.boundary_loops.1
    }

    /// Whether the Euler characteristic is unchanged.
    pub fn euler_unchanged(&self) -> bool {
        self.euler.0 == self.euler.1
    }

    /// No new defect and the same boundary-loop count and Euler characteristic.
    pub fn is_valid(&self) -> bool {
        self.new_non_manifold_edges == 0
            && self.duplicate_triangles == 0
            && self.degenerate_triangles == 0
            && self.new_folded_pairs == 0
            && self.out_of_range_triangles == 0
            && self.boundary_loops_unchanged()
            && self.euler_unchanged()
    }
}

/// Sorted vertex triple of a triangle.
type TriKey = [u32; 3];

fn sorted(t: [u32; 3]) -> TriKey {
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

fn unit_normal(m: &MeshData, t: [u32; 3]) -> Option<[f64; 3]> {
    let p = t.map(|i| m.positions[i as usize].map(f64::from));
    let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| n.map(|c| c / len))
}

/// Counts everything in [`Topology`].
pub fn analyse(mesh: &MeshData) -> Topology {
    analyse_full(mesh).0
}

/// [`analyse`], plus the folded pairs as (smaller, larger) sorted vertex triples.
fn analyse_full(mesh: &MeshData) -> (Topology, HashSet<(TriKey, TriKey)>) {
    let nv = mesh.positions.len();
    let mut topo = Topology {
        triangles: mesh.triangles.len(),
        ..Topology::default()
    };
    // Triangles taking part in edge counts: in range and not degenerate.
    let mut good: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len());
    let mut referenced = vec![false; nv];
    let mut vertex_sets = HashSet::with_capacity(mesh.triangles.len());
    let mut comp = Dsu::new(nv);
    for &t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= nv) {
            topo.out_of_range_triangles += 1;
            continue;
        }
        for &i in &t {
            referenced[i as usize] = true;
        }
        comp.union(t[0], t[1]);
        comp.union(t[1], t[2]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            topo.degenerate_triangles += 1;
            continue;
        }
        if !vertex_sets.insert(sorted(t)) {
            topo.duplicate_triangles += 1;
        }
        good.push(t);
    }
    topo.referenced_vertices = referenced.iter().filter(|&&r| r).count();
    topo.components = (0..nv as u32)
        .filter(|&v| referenced[v as usize] && comp.find(v) == v)
        .count();

    // Half-edges (lo, hi, triangle, forward), sorted so each edge's triangles are adjacent.
    let mut half: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(good.len() * 3);
    for (ti, t) in good.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), ti as u32, a < b));
        }
    }
    half.sort_unstable();
    let normals: Vec<Option<[f64; 3]>> = good.iter().map(|&t| unit_normal(mesh, t)).collect();
    let mut folded: HashSet<(TriKey, TriKey)> = HashSet::new();
    let mut boundary_graph: Vec<(u32, u32)> = Vec::new();
    for group in half.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        topo.edges += 1;
        match group.len() {
            1 => {
                topo.boundary_edges += 1;
                boundary_graph.push((group[0].0, group[0].1));
            }
            2 => {
                if group[0].3 == group[1].3 {
                    topo.inconsistent_edges += 1;
                }
            }
            _ => topo.non_manifold_edges += 1,
        }
        for (i, x) in group.iter().enumerate() {
            for y in &group[i + 1..] {
                let (Some(a), Some(b)) = (normals[x.2 as usize], normals[y.2 as usize]) else {
                    continue;
                };
                if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < FOLD_DOT {
                    let (ka, kb) = (sorted(good[x.2 as usize]), sorted(good[y.2 as usize]));
                    folded.insert((ka.min(kb), ka.max(kb)));
                }
            }
        }
    }
    topo.folded_pairs = folded.len();

    // Boundary loops: cycle rank E - V + C of the boundary-edge graph.
    let mut bdsu = Dsu::new(nv);
    let mut merges = 0usize;
    for &(a, b) in &boundary_graph {
        if bdsu.union(a, b) {
            merges += 1;
        }
    }
    // C = V - merges, so E - V + C = E - merges.
    topo.boundary_loops = boundary_graph.len() - merges;

    topo.non_manifold_vertices = count_pinched_vertices(nv, &good);
    topo.euler = topo.referenced_vertices as i64 - topo.edges as i64 + good.len() as i64;
    (topo, folded)
}

/// Vertices whose incident triangles form more than one fan connected through edges at the
/// vertex.
fn count_pinched_vertices(nv: usize, good: &[[u32; 3]]) -> usize {
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
    let mut pinched = 0;
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
            pinched += 1;
        }
    }
    pinched
}

/// Whether `output` is a valid simplification of `input` (same vertex numbering).
pub fn compare(input: &MeshData, output: &MeshData) -> Validity {
    let (ti, fi) = analyse_full(input);
    let (to, fo) = analyse_full(output);
    Validity {
        new_non_manifold_edges: to.non_manifold_edges.saturating_sub(ti.non_manifold_edges),
        duplicate_triangles: to.duplicate_triangles,
        degenerate_triangles: to.degenerate_triangles,
        new_folded_pairs: fo.difference(&fi).count(),
        out_of_range_triangles: to.out_of_range_triangles,
        boundary_loops: (ti.boundary_loops, to.boundary_loops),
        euler: (ti.euler, to.euler),
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
        writeln!(f, "  euler (V-E+F)          {}", t.euler)?;
        write!(f, "  components             {}", t.components)
    }
}

impl fmt::Display for Validity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self;
        let mark = |ok: bool| if ok { "ok" } else { "FAIL" };
        writeln!(
            f,
            "  new non-manifold edges {:<6} {}",
            v.new_non_manifold_edges,
            mark(v.new_non_manifold_edges == 0)
        )?;
        writeln!(
            f,
            "  duplicate triangles    {:<6} {}",
            v.duplicate_triangles,
            mark(v.duplicate_triangles == 0)
        )?;
        writeln!(
            f,
            "  degenerate triangles   {:<6} {}",
            v.degenerate_triangles,
            mark(v.degenerate_triangles == 0)
        )?;
        writeln!(
            f,
            "  new folded pairs       {:<6} {}",
            v.new_folded_pairs,
            mark(v.new_folded_pairs == 0)
        )?;
        writeln!(
            f,
            "  out-of-range triangles {:<6} {}",
            v.out_of_range_triangles,
            mark(v.out_of_range_triangles == 0)
        )?;
        writeln!(
            f,
            "  boundary loops         {} -> {} {}",
            v.boundary_loops.0,
            v.boundary_loops.1,
            mark(v.boundary_loops_unchanged())
        )?;
        writeln!(
            f,
            "  euler characteristic   {} -> {} {}",
            v.euler.0,
            v.euler.1,
            mark(v.euler_unchanged())
        )?;
        write!(f, "  => {}", if v.is_valid() { "VALID" } else { "INVALID" })
    }
}

/// `host-sim check ORIGINAL SIMPLIFIED`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The input mesh.
    pub original: std::path::PathBuf,
    /// The simplified mesh (same vertex numbering).
    pub simplified: std::path::PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `host-sim check`: topology of both meshes and the validity; exit code 1 if invalid.
pub fn run(args: &Args) -> anyhow::Result<std::process::ExitCode> {
    let a = crate::io::load(&args.original)?;
    let b = crate::io::load(&args.simplified)?;
    let (ta, tb, v) = (analyse(&a), analyse(&b), compare(&a, &b));
    if args.json {
        let j = serde_json::json!({
            "original": ta,
            "simplified": tb,
            "validity": v,
            "valid": v.is_valid(),
        });
        println!("{}", serde_json::to_string_pretty(&j)?);
    } else {
        println!("original {}:\n{ta}", args.original.display());
        println!("simplified {}:\n{tb}", args.simplified.display());
        println!("validity:\n{v}");
    }
    Ok(if v.is_valid() {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::from(1)
    })
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
    fn shared_meshes_match_sources_md() {
        // (file, V, E, boundary edges, loops, non-manifold vertices, euler, components)
        let expect = [
            ("cow.obj", 2903, 8706, 0, 0, 1, 1, 1),
            ("stanford_bunny.obj", 34834, 104288, 223, 5, 0, -3, 1),
            ("camelhead.obj", 11381, 34084, 56, 1, 0, 1, 1),
            ("plate_holes.obj", 618, 1878, 0, 0, 0, -8, 1),
        ];
        for (name, v, e, be, bl, nmv, eu, c) in expect {
            let p = std::path::Path::new("/work/shared/meshes").join(name);
            if !p.exists() {
                continue;
            }
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
