//! The clustering cases of `tests/golden/cluster.toml` (`host-sim qemu --cluster`): streaming
//! vertex clustering of meshes larger than a board's RAM. `<backend>/<name>.bin` holds the
//! compared result header and the output triangles, `<name>.txt` the same in words. The host
//! runs the firmware's library call ([`fn@reference`]: same `table_cells`, same output buffer
//! length, so the same hash slots) on the mesh in memory.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use meshfmt::cluster::{ClusterCase, ClusterResult, CLUSTER_CASE_LEN, CLUSTER_COMPARED_LEN};
use meshfmt::{Board as BoardId, IndexType};
use serde::Deserialize;
use tinydecimate::cluster::{ClusterReport, Scratch, SliceSource};

use crate::backend::Backend;

/// The case list inside the golden directory.
pub const MANIFEST: &str = "cluster.toml";

/// One `[[case]]` of `cluster.toml`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// Golden file name.
    pub name: String,
    /// What the case is for.
    #[serde(default)]
    pub about: String,
    /// A mesh file relative to the repository root .
    pub mesh: String,
    /// Target triangle count (0: `resolution`).
    #[serde(default)]
    pub target_triangles: u32,
    /// Cells along the longest side when there is no target.
    #[serde(default)]
    pub resolution: u32,
    /// Cells of the table the call uses (`ClusterConfig::table_cells`).
    pub table_cells: u32,
    /// Length of the output buffer, in triangles.
    pub output_slots: u32,
    /// Refine passes of the target search.
    #[serde(default = "two")]
    pub refine_passes: u32,
    /// `nearest` or `quadric`.
    pub representative: String,
    /// `u16` or `u32` output.
    pub index: String,
    /// Load the mesh into RAM first (measures the library without the semihosting reads).
    #[serde(default)]
    pub in_ram: bool,
    /// The boards the case is too big for (skipped there, and only there).
    #[serde(default)]
    pub skip: Vec<String>,
}

fn two() -> u32 {
    2
}

#[derive(Deserialize)]
struct Manifest {
    case: Vec<Spec>,
}

/// Reads `dir/cluster.toml`.
pub fn load_specs(dir: &Path) -> Result<Vec<Spec>> {
    let path = dir.join(MANIFEST);
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let m: Manifest = toml::from_str(&text).with_context(|| format!("{}", path.display()))?;
    Ok(m.case)
}

impl Spec {
    /// The case header (vertex and triangle counts from the mesh).
    pub fn header(&self, vertices: usize, triangles: usize) -> Result<ClusterCase> {
        Ok(ClusterCase {
            index_type: match self.index.as_str() {
                "u16" => IndexType::U16,
                "u32" => IndexType::U32,
                x => bail!("case {}: index {x:?} (u16 or u32)", self.name),
            },
            quadric: match self.representative.as_str() {
                "nearest" => false,
                "quadric" => true,
                x => bail!(
                    "case {}: representative {x:?} (nearest or quadric)",
                    self.name
                ),
            },
            vertices: meshfmt::narrow(vertices),
            triangles: meshfmt::narrow(triangles),
            target_triangles: self.target_triangles,
            resolution: self.resolution,
            table_cells: self.table_cells,
            output_slots: self.output_slots,
            refine_passes: self.refine_passes,
            in_ram: self.in_ram,
        })
    }
}

/// A loaded case: header and mesh.
pub struct Case {
    pub spec: Spec,
    pub header: ClusterCase,
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl Case {
    /// Loads the mesh of `spec`.
    pub fn load(spec: &Spec) -> Result<Case> {
        let path = crate::repo_root().join(&spec.mesh);
        let m = crate::io::load(&path).with_context(|| format!("case {}", spec.name))?;
        Ok(Case {
            header: spec.header(m.positions.len(), m.triangles.len())?,
            spec: spec.clone(),
            positions: m.positions,
            triangles: m.triangles,
        })
    }

    /// The case file.
    pub fn encode(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(
            CLUSTER_CASE_LEN + 12 * self.positions.len() + 12 * self.triangles.len(),
        );
        b.extend_from_slice(&self.header.to_bytes());
        for p in &self.positions {
            for c in p {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        for t in &self.triangles {
            for i in t {
                b.extend_from_slice(&i.to_le_bytes());
            }
        }
        b
    }
}

/// The host's table: as large as any board's (the case's `table_cells` picks the part used).
/// The same library call as the firmware's, on the host: the result header (measurement block
/// zero) and the output triangles in the case's index type, little-endian.
pub fn reference(case: &Case) -> Result<(ClusterResult, Vec<u8>)> {
    // The harness's one table: larger than any board's, `table_cells` picks the part used.
    crate::cluster::with_tables(|table, quads| {
        let h = &case.header;
        let config = meshfmt::cluster::lib::config(h);
        let q = if h.quadric { Some(&mut *quads) } else { None };
        let mut src = SliceSource::new(&case.positions, &case.triangles);
        let n = h.output_slots as usize;
        // One call per index type: the same library call, the triangles as little-endian bytes.
        macro_rules! run {
            ($index:ty) => {{
                let mut out = vec![[<$index>::default(); 3]; n];
                let r = table.cluster(
                    &mut src,
                    &config,
                    &mut out,
                    Scratch {
                        quadrics: q,
                        ..Scratch::new()
                    },
                );
                let k = r.as_ref().map_or(0, |r| r.triangles_out);
                let b: Vec<u8> = out[..k]
                    .iter()
                    .flatten()
                    .flat_map(|v| v.to_le_bytes())
                    .collect();
                (r, b)
            }};
        }
        let (outcome, bytes): (Result<ClusterReport, _>, Vec<u8>) = match h.index_type {
            IndexType::U16 => run!(u16),
            IndexType::U32 => run!(u32),
        };
        Ok((
            meshfmt::cluster::lib::result(h.index_type, &outcome, BoardId::Host),
            bytes,
        ))
    })
}

/// What is compared: the result header's first [`CLUSTER_COMPARED_LEN`] bytes, then the
/// triangles.
pub fn compared(r: &ClusterResult, triangles: &[u8]) -> Vec<u8> {
    let mut b = r.to_bytes()[..CLUSTER_COMPARED_LEN].to_vec();
    b.extend_from_slice(triangles);
    b
}

/// The golden result in words (`<name>.txt`).
pub fn summary(case: &Case, r: &ClusterResult, triangles: &[u8]) -> String {
    format!(
        "# host-sim qemu --cluster: {name}\nmesh = {mesh:?}\nstatus = {status:?}\nerror = {kind:?} {err:?}\n\
         triangles_in = {tin}\ntriangles_out = {tout}\ncollapsed = {col}\nduplicates = {dup}\n\
         opposite_duplicates = {opp}\ncells = {cells}\npasses = {passes}\ntarget_triangles = {target}\n\
         grid = {n} ({dx} x {dy} x {dz} cells of {cell})\ntriangles_sha256 = {sha:?}\n",
        name = case.spec.name,
        mesh = case.spec.mesh,
        status = r.status,
        kind = r.error_kind,
        err = r.error,
        tin = r.triangles_in,
        tout = r.triangles_out,
        col = r.collapsed,
        dup = r.duplicates,
        opp = r.opposite_duplicates,
        cells = r.cells,
        passes = r.passes,
        target = r.target_triangles,
        n = r.grid_n,
        dx = r.grid_dims[0],
        dy = r.grid_dims[1],
        dz = r.grid_dims[2],
        cell = r.grid_cell,
        sha = crate::golden::sha256_hex(triangles),
    )
}

pub fn golden_paths(dir: &Path, backend: Backend, name: &str) -> (PathBuf, PathBuf) {
    let d = dir.join(backend.to_string());
    (d.join(format!("{name}.bin")), d.join(format!("{name}.txt")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use meshfmt::Status;

    /// The host's run of every clustering case equals its golden file (the boards are checked
    /// by `host-sim qemu --cluster`).
    #[test]
    fn host_matches_the_cluster_goldens() {
        let dir = crate::golden::default_dir();
        let backend = Backend::compiled();
        for spec in load_specs(&dir).unwrap() {
            let case = Case::load(&spec).unwrap();
            let (r, tri) = reference(&case).unwrap();
            let (bin, _) = golden_paths(&dir, backend, &spec.name);
            let want = std::fs::read(&bin).unwrap();
            assert!(
                compared(&r, &tri) == want,
                "{}: differs from {}",
                spec.name,
                bin.display()
            );
            assert_eq!(r.status, Status::Ok, "{}", spec.name);
        }
    }

    #[test]
    fn case_files_round_trip() {
        let spec = Spec {
            name: "t".into(),
            about: String::new(),
            mesh: "tests/fixtures/cow.obj".into(),
            target_triangles: 100,
            resolution: 0,
            table_cells: 200,
            output_slots: 150,
            refine_passes: 2,
            representative: "nearest".into(),
            index: "u32".into(),
            in_ram: false,
            skip: vec![],
        };
        let case = Case::load(&spec).unwrap();
        let b = case.encode();
        let h = ClusterCase::from_bytes(b[..CLUSTER_CASE_LEN].try_into().unwrap()).unwrap();
        assert_eq!(h, case.header);
        assert_eq!(
            b.len() as u64,
            h.triangles_at() + 12 * u64::from(h.triangles)
        );
        let (r, tri) = reference(&case).unwrap();
        assert_eq!(r.status, Status::Ok);
        assert!(r.triangles_out > 0 && r.triangles_out <= 100);
        assert_eq!(tri.len(), 12 * r.triangles_out as usize);
    }
}
