//! `tinydecimate simplify` on meshes with vertex attributes: glTF/GLB ([`crate::io::gltf`]), OBJ
//! with `vt`/`vn` ([`crate::io::objattr`]) and PLY with vertex properties besides x, y, z
//! ([`crate::io::plyattr`]).
//!
//! The primitives of one glTF mesh (the material groups of one OBJ) are simplified together,
//! as one mesh ([`join`]): their vertices side by side, so that with welded seams a boundary
//! between two materials is a seam like a texture's, whose two sides move together and keep
//! their own attributes, and each output triangle is handed back to the part its corners came
//! from ([`split`]). `--per-primitive` simplifies each part on its own instead, with the same
//! configuration, and a boundary between materials then moves separately on each side (the
//! gaps meshoptimizer's and gltfpack's per-primitive runs open). `--target-triangles N` is
//! shared among the runs in proportion to their triangles. The validity check (and with
//! `--measure` the Metro error and the texture figures) runs per run, in the mesh's own
//! coordinates (node transforms are not applied); the result is valid when every run's is.
//! For each glTF mesh (OBJ file) of several parts the report gives its open edges welded by
//! position across all its parts, the input's and the result's ([`gaps`]): a gap between
//! materials shows there.
//! The attributes of every kept vertex are those of an input vertex, bit for bit, because the
//! library's subset placement only moves triangles. Optimal placement moves vertices without
//! interpolating attributes, so `--placement optimal` is refused here.

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use tinydecimate::{Config, Report, Target};

use super::shading::{self, Shading};
use super::{Args, PlacementArg, QuadricArg};
use crate::io::MeshData;

/// The one call into the library: `mesh`'s triangles simplified (input numbering) and the
/// report.
/// `attributes`: `--attribute-weights`' attribute term (`super::attributes`).
fn run_library(
    mesh: &MeshData,
    config: &Config,
    args: &Args,
    attributes: Option<&crate::simplify::Attributes>,
) -> Result<(Vec<[u32; 3]>, Report, Duration)> {
    if let Some(mode) = args.pipeline() {
        let config = &config.with_prune_parts(args.prunes());
        if args.seams == super::SeamsArg::Weld {
            let (out, report, elapsed) =
                crate::simplify::simplify_pipeline_wedges(mesh, config, mode, args.integer)?;
            return Ok((out.triangles, report, elapsed));
        }
        let (out, report, elapsed) =
            crate::simplify::simplify_pipeline(mesh, config, false, mode, args.integer)?;
        return Ok((out.triangles, report, elapsed));
    }
    let stored = args.quadric == QuadricArg::Stored;
    let placement = stored.then_some(tinydecimate::cost::Placement::Subset);
    let run = crate::simplify::Run {
        operator: args.operator,
        placement,
        bounded: args.max_error.is_some(),
        weld: args.seams == super::SeamsArg::Weld,
        // The attributes are carried: a corner where more than two of them meet stays.
        lock_seam_corners: true,
        ..Default::default()
    };
    let (out, report, elapsed) =
        crate::simplify::simplify_with_attributes(mesh, config, &run, attributes)?;
    Ok((out.triangles, report, elapsed))
}

/// Whether the output is glTF: `--format glb`, or without `--format` a `.gltf` or `.glb` name.
fn gltf_out(args: &Args) -> bool {
    match args.format {
        Some(f) => f == super::OutputFormat::Glb,
        None => crate::io::gltf::is_gltf_path(&args.output),
    }
}

/// Runs `simplify` here when the input or output is glTF, or the input is an OBJ with texture
/// coordinates or normals written to OBJ; `None` leaves the run to the plain path.
/// `--integer`: `positions` put on the grid the run will see, in place (`pipeline::quantise`
/// over all of them: one frame), so that the run, its check and the file written all have the
/// grid's positions; with the input's a fold the grid's rounding hid could show. The run's
/// own quantisation of a part of them is then exact: its cell divides this one.
fn onto_grid(positions: &mut [[f32; 3]]) -> Result<()> {
    let mut grid = vec![[0u16; 3]; positions.len()];
    let frame =
        tinydecimate::pipeline::quantise(positions, &mut grid).map_err(|e| anyhow!("{e}"))?;
    for (p, &q) in positions.iter_mut().zip(&grid) {
        *p = frame.position(q);
    }
    Ok(())
}

/// `--integer` on an OBJ with attributes: its `v` positions on the grid, the text of each
/// `v` line rewritten (what follows x, y and z, a vertex colour, kept).
fn obj_onto_grid(f: &mut crate::io::objattr::ObjFile) -> Result<()> {
    onto_grid(&mut f.positions)?;
    for (text, p) in f.v_text.iter_mut().zip(&f.positions) {
        let rest: Vec<&str> = text.split_whitespace().skip(3).collect();
        let mut line = format!("{} {} {}", p[0], p[1], p[2]);
        for r in rest {
            line.push(' ');
            line.push_str(r);
        }
        *text = line;
    }
    Ok(())
}

/// `--integer` on a PLY with vertex properties: its positions on the grid, written into each
/// vertex's `x`, `y`, `z` (float or double; integer coordinates cannot hold the grid's).
fn ply_onto_grid(f: &mut crate::io::plyattr::PlyFile) -> Result<()> {
    use ply_rs_bw::ply::Property;
    onto_grid(&mut f.mesh.positions)?;
    for (v, p) in f.vertices.iter_mut().zip(&f.mesh.positions) {
        for (name, x) in ["x", "y", "z"].into_iter().zip(p) {
            match v.get_mut(name) {
                Some(Property::Float(c)) => *c = *x,
                Some(Property::Double(c)) => *c = f64::from(*x),
                _ => bail!("--integer: the PLY's {name} is not a float property"),
            }
        }
    }
    Ok(())
}

/// `--integer` on glTF: each mesh's positions (all its primitives, one frame: they are one
/// run) on the grid, in the primitives and in their `POSITION` data (float, as core glTF has
/// it; the loader refuses `KHR_mesh_quantization`, and a quantised one could not hold another
/// grid).
fn gltf_onto_grid(f: &mut crate::io::gltf::GltfFile) -> Result<()> {
    let meshes = f
        .primitives
        .iter()
        .map(|p| p.mesh)
        .max()
        .map_or(0, |m| m + 1);
    for m in 0..meshes {
        let mut all: Vec<[f32; 3]> = f
            .primitives
            .iter()
            .filter(|p| p.mesh == m)
            .flat_map(|p| p.positions.iter().copied())
            .collect();
        onto_grid(&mut all)?;
        let mut next = all.into_iter();
        for p in f.primitives.iter_mut().filter(|p| p.mesh == m) {
            for q in p.positions.iter_mut() {
                *q = next.next().unwrap_or(*q);
            }
            let label = crate::io::gltf::label(p);
            let Some(s) = p.attributes.iter_mut().find(|s| s.semantic == "POSITION") else {
                continue;
            };
            if s.component_type != crate::io::gltf::FLOAT || s.elem != 12 {
                bail!("--integer: {label}'s POSITION is not float: it cannot hold the grid");
            }
            for (d, q) in s.data.chunks_exact_mut(12).zip(&p.positions) {
                for (b, x) in d.chunks_exact_mut(4).zip(q) {
                    b.copy_from_slice(&x.to_le_bytes());
                }
            }
        }
    }
    Ok(())
}

pub fn run_if_attributes(args: &Args) -> Result<Option<ExitCode>> {
    let (i, o) = (&args.input, &args.output);
    let gi = crate::io::gltf::is_gltf_path(i);
    let go = gltf_out(args);
    if gi || go {
        if !gi {
            bail!(
                "glTF is written only from glTF: give {} a .gltf or .glb extension, or write {} \
                 as OBJ, PLY or STL",
                i.display(),
                o.display()
            );
        }
        refuse_optimal(args)?;
        // The output is checked before the long work, as on the plain path. glTF in, another
        // format out: the same parts simplified, written by `io::save_gltf_as`.
        if crate::io::is_std(o) {
            bail!("glTF input is written to a file, not to standard output: give an output path");
        }
        if !go {
            crate::io::check_writable(o, args.mesh_format())?;
        } else if o.is_dir() {
            bail!("{}: is a directory, not a file to write", o.display());
        }
        if !o.exists() {
            std::fs::File::create(o).map_err(|e| anyhow!("{}: cannot create: {e}", o.display()))?;
            let _ = std::fs::remove_file(o);
        }
        return run_gltf(args).map(Some);
    }
    let is_obj = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    };
    if is_obj(i)
        && is_obj(o)
        && crate::io::check_writable(o, args.mesh_format()).is_ok()
        && args
            .mesh_format()
            .is_none_or(|f| f == crate::io::Format::Obj)
        && !args.keep_numbering
    {
        let t0 = Instant::now();
        let bytes = std::fs::read(i).map_err(|e| anyhow!("{}: cannot read: {e}", i.display()))?;
        if crate::io::objattr::has_attributes(&bytes) {
            refuse_optimal(args)?;
            return run_obj(args, &bytes, t0).map(Some);
        }
    }
    let is_ply = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("ply"))
    };
    if is_ply(i)
        && is_ply(o)
        && crate::io::check_writable(o, args.mesh_format()).is_ok()
        && args
            .mesh_format()
            .is_none_or(|f| f == crate::io::Format::Ply)
        && !args.keep_numbering
    {
        let t0 = Instant::now();
        let bytes = std::fs::read(i).map_err(|e| anyhow!("{}: cannot read: {e}", i.display()))?;
        let extra = crate::io::plyattr::extra_properties(&bytes);
        if !extra.is_empty() {
            refuse_optimal(args)?;
            return run_ply(args, &bytes, &extra, t0).map(Some);
        }
    }
    Ok(None)
}

fn run_ply(args: &Args, bytes: &[u8], extra: &[String], t0: Instant) -> Result<ExitCode> {
    let mut file =
        crate::io::plyattr::parse(bytes).map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    if args.integer {
        ply_onto_grid(&mut file)?;
    }
    let parts = vec![("vertex element".to_string(), file.mesh.clone(), None, None)];
    let mut times = Times {
        read: t0.elapsed(),
        ..Times::default()
    };
    let done = simplify_parts(args, &parts, &[])?;
    let t0 = Instant::now();
    let out = crate::io::plyattr::write(&file, &done[0].triangles)
        .map_err(|e| anyhow!("{}: {e}", args.output.display()))?;
    std::fs::write(&args.output, out)
        .map_err(|e| anyhow!("{}: cannot write: {e}", args.output.display()))?;
    times.write = t0.elapsed();
    let head = format!(
        "simplify {} -> {} (PLY, vertex properties {} kept per vertex): {} -> {} triangles\n",
        args.input.display(),
        args.output.display(),
        extra.join(", "),
        file.mesh.triangles.len(),
        done[0].triangles.len()
    );
    finish(args, head, &done, &[], times)
}

fn refuse_optimal(args: &Args) -> Result<()> {
    if args.meshopt_out.is_some() {
        bail!(
            "{}: the mesh has vertex attributes (texture coordinates, normals, ...) and \
             --meshopt-out writes meshoptimizer's positions-only result: give a mesh without \
             them (STL, or PLY or OBJ with positions only)",
            args.input.display()
        );
    }
    if args.quadric == QuadricArg::Stored && args.placement == PlacementArg::Optimal {
        bail!(
            "{}: the mesh has vertex attributes (texture coordinates, normals, ...) and optimal \
             placement moves vertices without interpolating them: use --placement subset",
            args.input.display()
        );
    }
    Ok(())
}

/// One part's outcome.
struct Part {
    /// Time in the library, and in welding hard edges and mapping the result back.
    library: Duration,
    welding: Duration,
    triangles: Vec<[u32; 3]>,
    /// The part's target, and whether it stopped short of it.
    target: usize,
    short: bool,
    line: String,
    valid: bool,
    json: serde_json::Value,
}

/// One part to simplify: its label, its mesh, when it has them the texture coordinates its
/// material reads (one per vertex, for the UV stretch figure), and its vertices grouped by
/// position and non-shading attributes (for `--hard-edges weld`).
type Input = (String, MeshData, Option<Vec<[f32; 2]>>, Option<Shading>);

/// Simplifies each mesh of `parts` with `args`' configuration; `normals` (per part, may be
/// shorter) are only read by `--attribute-weights`.
fn simplify_parts(
    args: &Args,
    parts: &[Input],
    normals: &[Option<Vec<[f32; 3]>>],
) -> Result<Vec<Part>> {
    let total: usize = parts.iter().map(|(_, m, _, _)| m.triangles.len()).sum();
    let mut out = Vec::new();
    for (k, (label, mesh, uvs, shading)) in parts.iter().enumerate() {
        let mut config = args.config();
        if let Some(n) = args.target_triangles {
            let share = (n as f64 * mesh.triangles.len() as f64 / total.max(1) as f64).round();
            config = config.with_target(Target::Triangles(share as usize));
        }
        let config = args.with_distances(config, &mesh.positions)?;
        // Hard edges welded: the library and meshoptimizer's anchor see the keyed mesh.
        let shading = shading.as_ref().filter(|s| {
            // With split seams every split is a boundary the user asked for, hard edges too
            // (and the check compares the file's vertices, which welding would pinch).
            args.hard_edges == super::HardEdgesArg::Weld
                && args.seams == super::SeamsArg::Weld
                && s.welds()
        });
        let t0 = Instant::now();
        let keyed = shading.map(|s| s.keyed(mesh));
        let mut welding = t0.elapsed();
        let lib_mesh = keyed.as_ref().unwrap_or(mesh);
        // The keyed mesh keeps the positions' numbering: the attributes are the input's.
        let attributes = super::attributes::for_part(
            args,
            label,
            mesh.positions.len(),
            uvs.as_deref(),
            normals.get(k).and_then(Option::as_deref),
        )?;
        let (tris, report, library) = run_library(
            lib_mesh,
            &config,
            &args.resolve(lib_mesh),
            attributes.as_ref(),
        )
        .map_err(|e| anyhow!("{label}: {e}"))?;
        let t0 = Instant::now();
        let tris = match shading {
            Some(s) => s.restore(mesh, &tris),
            None => tris,
        };
        welding += t0.elapsed();
        let result = MeshData {
            positions: mesh.positions.clone(),
            triangles: tris.clone(),
        };
        let head = format!(
            "  {label}: {} -> {} triangles (target {}, stop {:?})",
            report.triangles_in, report.triangles_out, report.target_triangles, report.stop,
        );
        // The report and the advice, each line its own.
        let mut tail = if parts.len() == 1 {
            format!("\n{}", crate::simplify::format_report(&report).trim_end())
        } else {
            String::new()
        };
        // Why it stopped short, per part; the fallback is for the whole file (`finish`).
        let advice = super::advice_for(args, &report).map(|(outcome, mut a)| {
            a.fallback = None;
            a.fallback_then_collapse = None;
            let _ = write!(tail, "\n{}", a.text(&outcome, "    ").trim_end());
            a
        });
        let mut json = serde_json::json!({
            "part": label,
            "report": crate::simplify::report_json(&report),
            "advice": advice,
        });
        let weld = args.seams == super::SeamsArg::Weld;
        let v = crate::check::compare_opts(mesh, &result, false, weld);
        let valid = v.is_valid();
        let mut verdict = String::from(if valid { "valid" } else { "NOT valid" });
        json["valid"] = serde_json::Value::Bool(valid);
        json["defects"] =
            serde_json::json!(v.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>());
        json["metro"] = serde_json::Value::Null;
        if args.measure {
            let opts = crate::metro::MetroOptions {
                samples_per_triangle: args.samples_per_triangle,
                progress: false,
                ..Default::default()
            };
            let m = crate::metro::metro(mesh, &result, &opts);
            let _ = write!(
                verdict,
                ", Metro max {:.4} % mean {:.4} % of the diagonal",
                m.hausdorff_pct, m.symmetric_mean_pct
            );
            json["metro"] = serde_json::to_value(&m)?;
        }
        // One part: the verdict on a line of its own after the report and the advice; several:
        // after the part's one-line head.
        let mut line = if parts.len() == 1 {
            format!("{head}{tail}\n  check                  {verdict}")
        } else {
            format!("{head}, {verdict}{tail}")
        };
        for d in v.describe_by_kind(3).lines() {
            let _ = write!(line, "\n  {d}");
        }
        if let (true, Some(uvs)) = (args.measure, uvs) {
            let _ = write!(
                line,
                "{}{}",
                uv_stretch(mesh, keyed.as_ref(), uvs, &result, &mut json),
                super::attributes::meshopt_reference(mesh, uvs, &result, &attributes, &mut json)
            );
        }
        out.push(Part {
            library,
            welding,
            triangles: tris,
            target: report.target_triangles,
            short: advice.is_some(),
            line,
            valid,
            json,
        });
    }
    Ok(out)
}

/// The parts of one run: indices into the file's parts, and where each part's vertices start
/// in the joined numbering.
struct Group {
    members: Vec<usize>,
    offsets: Vec<u32>,
}

/// The runs for `parts`: with `--per-primitive` (or one part) each part alone, else the parts
/// of each key (`key_of`: a glTF primitive's mesh) together, in order of first appearance.
fn groups(args: &Args, parts: &[Input], key_of: impl Fn(usize) -> usize) -> Vec<Group> {
    let mut out: Vec<(usize, Group)> = Vec::new();
    for i in 0..parts.len() {
        let key = key_of(i);
        let group = match out
            .iter_mut()
            .find(|(k, _)| !args.per_primitive && *k == key)
        {
            Some((_, g)) => g,
            None => {
                out.push((
                    key,
                    Group {
                        members: Vec::new(),
                        offsets: Vec::new(),
                    },
                ));
                &mut out.last_mut().expect("just pushed").1
            }
        };
        let start = group
            .members
            .last()
            .zip(group.offsets.last())
            .map_or(0, |(&m, &o)| o + parts[m].1.positions.len() as u32);
        group.members.push(i);
        group.offsets.push(start);
    }
    out.into_iter().map(|(_, g)| g).collect()
}

/// One run's input: the group's parts side by side (each part's vertices numbered after the
/// previous part's), labelled `label`; texture coordinates, hard-edge groupings and normals
/// when every part has them. A single part is itself.
fn join(
    label: String,
    group: &Group,
    parts: &[Input],
    normals: &[Option<Vec<[f32; 3]>>],
) -> (Input, Option<Vec<[f32; 3]>>) {
    if let [k] = group.members[..] {
        return (parts[k].clone(), normals.get(k).cloned().flatten());
    }
    let members: Vec<&Input> = group.members.iter().map(|&k| &parts[k]).collect();
    let mut mesh = MeshData::default();
    for ((_, m, _, _), &offset) in members.iter().zip(&group.offsets) {
        mesh.positions.extend_from_slice(&m.positions);
        mesh.triangles
            .extend(m.triangles.iter().map(|t| t.map(|i| i + offset)));
    }
    let uvs = members
        .iter()
        .map(|(_, _, uv, _)| uv.as_ref())
        .collect::<Option<Vec<_>>>()
        .map(|u| u.iter().flat_map(|v| v.iter().copied()).collect());
    let shading = members
        .iter()
        .map(|(_, _, _, s)| s.as_ref())
        .collect::<Option<Vec<_>>>()
        .map(|s| Shading::concat(&s));
    let normals = group
        .members
        .iter()
        .map(|&k| normals.get(k).and_then(Option::as_ref))
        .collect::<Option<Vec<_>>>()
        .map(|n| n.iter().flat_map(|v| v.iter().copied()).collect());
    ((label, mesh, uvs, shading), normals)
}

/// A run's result handed back to its parts, each in its own numbering: a triangle goes to the
/// part of its corners. An error if a triangle's corners come from two parts (a triangle
/// that would take two materials, which the seam rules never make).
fn split(group: &Group, parts: &[Input], triangles: &[[u32; 3]]) -> Result<Vec<Vec<[u32; 3]>>> {
    let mut out = vec![Vec::new(); group.members.len()];
    let part_of = |v: u32| group.offsets.iter().rposition(|&o| o <= v).unwrap_or(0);
    for t in triangles {
        let k = part_of(t[0]);
        if part_of(t[1]) != k || part_of(t[2]) != k {
            bail!(
                "a result triangle {t:?} takes corners from two of {}'s parts",
                parts[group.members[0]].0
            );
        }
        out[k].push(t.map(|v| v - group.offsets[k]));
    }
    Ok(out)
}

/// Open edges (used by one triangle) of a mesh's parts welded by position, and how many of
/// them the input did not have: an edge whose two ends were not both on the welded input's
/// boundary. A gap between two materials opens such edges; simplifying a boundary the input
/// had only shortens it.
pub(crate) fn gaps(input: &[&MeshData], output: &[&MeshData]) -> (usize, usize, usize) {
    use std::collections::HashMap;
    let weld = |meshes: &[&MeshData], ids: &mut HashMap<[u32; 3], u32>| {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for m in meshes {
            let id: Vec<u32> = m
                .positions
                .iter()
                .map(|p| {
                    let n = ids.len() as u32;
                    *ids.entry(p.map(f32::to_bits)).or_insert(n)
                })
                .collect();
            for t in &m.triangles {
                let w = t.map(|v| id[v as usize]);
                for k in 0..3 {
                    let (a, b) = (w[k], w[(k + 1) % 3]);
                    if a != b {
                        *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                    }
                }
            }
        }
        edges
            .into_iter()
            .filter(|&(_, n)| n == 1)
            .map(|(e, _)| e)
            .collect::<Vec<_>>()
    };
    let mut ids = HashMap::new();
    let open_in = weld(input, &mut ids);
    let on_border: std::collections::HashSet<u32> =
        open_in.iter().flat_map(|&(a, b)| [a, b]).collect();
    let open_out = weld(output, &mut ids);
    let new = open_out
        .iter()
        .filter(|(a, b)| !(on_border.contains(a) && on_border.contains(b)))
        .count();
    (open_in.len(), open_out.len(), new)
}

/// The texture figures ([`crate::uvstretch`]: UV stretch, texture deviation, triangles torn
/// between charts) of the input, the result and meshoptimizer's `simplify` at the result's
/// triangle count: on the input's vertices as the file has them, and, when `keyed` is given
/// (hard edges welded), on the mesh ours saw too. As text for the part's line and into `json`.
fn uv_stretch(
    mesh: &MeshData,
    #[cfg_attr(not(feature = "meshopt"), allow(unused_variables))] keyed: Option<&MeshData>,
    uvs: &[[f32; 2]],
    result: &MeshData,
    json: &mut serde_json::Value,
) -> String {
    let stretch = |t: &[[u32; 3]]| crate::uvstretch::l2_stretch(&mesh.positions, uvs, t);
    let (Some(input), Some(_)) = (stretch(&mesh.triangles), stretch(&result.triangles)) else {
        return String::new();
    };
    let diag = mesh.bbox_diagonal().max(f64::MIN_POSITIVE);
    let figures = |t: &[[u32; 3]]| {
        let dev = crate::uvstretch::texture_deviation(&mesh.positions, uvs, &mesh.triangles, t)
            .map(|(mean, max, lost)| (100.0 * mean / diag, 100.0 * max / diag, lost));
        let torn = crate::uvstretch::torn_triangles(&mesh.positions, uvs, &mesh.triangles, t);
        serde_json::json!({
            "triangles": t.len(),
            "uv_stretch": stretch(t),
            "texture_deviation_pct": dev.map(|d| [d.0, d.1]),
            "texture_samples_lost": dev.map(|d| d.2),
            "torn_triangles": torn,
        })
    };
    let text = |j: &serde_json::Value| {
        let mut s = format!(
            "UV stretch {}",
            j["uv_stretch"]
                .as_f64()
                .map_or("-".into(), |t| format!("{t:.4}"))
        );
        if let (Some(d), Some(lost)) = (
            j["texture_deviation_pct"].as_array(),
            j["texture_samples_lost"].as_u64(),
        ) {
            let _ = write!(
                s,
                ", texture deviation mean {:.4} % max {:.4} %, {lost} samples lost",
                d[0].as_f64().unwrap_or(f64::NAN),
                d[1].as_f64().unwrap_or(f64::NAN)
            );
        }
        let _ = write!(
            s,
            ", {} triangles torn between charts",
            j["torn_triangles"].as_u64().unwrap_or(0)
        );
        s
    };
    let mine = figures(&result.triangles);
    #[cfg_attr(not(feature = "meshopt"), allow(unused_mut))]
    let mut out = format!("\n    {} (input {input:.4})", text(&mine));
    #[cfg_attr(not(feature = "meshopt"), allow(unused_mut))]
    let mut anchors: Vec<serde_json::Value> = Vec::new();
    // meshoptimizer's figures beside ours, when it is built in.
    #[cfg(feature = "meshopt")]
    for (what, m) in [
        ("the file's vertices", Some(mesh)),
        ("hard edges welded", keyed),
    ] {
        let Some(m) = m else { continue };
        let (anchor, _, _) = crate::meshopt::meshopt_simplify(m, result.triangles.len());
        let j = figures(&anchor.triangles);
        let _ = write!(
            out,
            "\n    meshoptimizer on {what}, at {} triangles: {}",
            anchor.triangles.len(),
            text(&j)
        );
        anchors.push(serde_json::json!({"mesh": what, "figures": j}));
    }
    json["texture"] = serde_json::json!({
        "input_uv_stretch": input,
        "result": mine,
        "meshopt": anchors,
    });
    out
}

/// Where a run's time went, outside the checks and measurements.
#[derive(Clone, Copy, Debug, Default)]
struct Times {
    /// Reading and parsing the input file.
    read: Duration,
    /// Grouping vertices by position and non-shading attributes, renaming corners and
    /// mapping the result back (`--hard-edges weld`), over all parts.
    welding: Duration,
    /// In the library, over all parts.
    library: Duration,
    /// Compacting and writing the output file.
    write: Duration,
}

impl Times {
    fn text(&self) -> String {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let all = ms(self.read) + ms(self.welding) + ms(self.library) + ms(self.write);
        format!(
            "time: reading {:.1} ms, hard edges {:.1} ms, library {:.1} ms, writing {:.1} ms (reading and writing {:.0} % of the four)",
            ms(self.read),
            ms(self.welding),
            ms(self.library),
            ms(self.write),
            100.0 * (ms(self.read) + ms(self.write)) / all.max(f64::MIN_POSITIVE)
        )
    }

    fn json(&self) -> serde_json::Value {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        serde_json::json!({
            "read_ms": ms(self.read),
            "hard_edges_ms": ms(self.welding),
            "library_ms": ms(self.library),
            "write_ms": ms(self.write),
        })
    }
}

fn finish(
    args: &Args,
    head: String,
    parts: &[Part],
    gaps: &[Gap],
    mut times: Times,
) -> Result<ExitCode> {
    for p in parts {
        times.library += p.library;
        times.welding += p.welding;
    }
    let valid = parts.iter().all(|p| p.valid);
    // A part stopped short: clustering reaches the file's count (on positions only; it reads
    // no glTF).
    let fallback = (parts.iter().any(|p| p.short) && !crate::gltf::is_gltf_path(&args.input))
        .then(|| {
            super::advice::fallbacks(
                &args.input.display().to_string(),
                &args.output.display().to_string(),
                parts.iter().map(|p| p.target).sum(),
            )
        })
        .flatten();
    if args.json {
        let mut j = serde_json::json!({
            "input": args.input.display().to_string(),
            "output": args.output.display().to_string(),
            "parts": parts.iter().map(|p| p.json.clone()).collect::<Vec<_>>(),
            "triangles_out": parts.iter().map(|p| p.triangles.len()).sum::<usize>(),
            "valid": valid,
            "fallback": fallback.as_ref().map(|f| [&f.0, &f.1]),
            "time": times.json(),
            "welded_parts": gaps.iter().map(|g| serde_json::json!({
                "mesh": g.mesh,
                "open_edges_in": g.open.0,
                "open_edges_out": g.open.1,
                "new_open_edges": g.open.2,
            })).collect::<Vec<_>>(),
        });
        if let [p] = parts {
            // One part: its report where the plain path puts it.
            j["report"] = p.json["report"].clone();
        }
        crate::outln!("{}", serde_json::to_string_pretty(&j)?);
    } else {
        let mut text = head;
        if args.integer {
            let _ = writeln!(
                text,
                "  in integers: the positions put on a 15-bit grid before the run (one per \
                 glTF mesh, or per file), and written as the grid's"
            );
        }
        for p in parts {
            let _ = writeln!(text, "{}", p.line);
        }
        for g in gaps {
            let (i, o, new) = g.open;
            let _ = writeln!(
                text,
                "  {}, its parts welded by position: {i} open edges in, {o} out, {new} of them \
                 new{}",
                g.mesh,
                if new > 0 { " (gaps between parts)" } else { "" }
            );
        }
        if !args.measure {
            let _ = writeln!(text, "  {}", super::NOT_MEASURED);
        }
        let _ = writeln!(text, "  {}", times.text());
        if let Some((alone, then)) = &fallback {
            let _ = writeln!(
                text,
                "  fallback: {alone} (vertex clustering: reaches the count)\n            {then} \
                 (clusters to at most twice the count, then collapses: lower error)\n            \
                 both read positions only: the attributes are not carried"
            );
        }
        crate::out!("{text}");
    }
    Ok(if valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn run_gltf(args: &Args) -> Result<ExitCode> {
    let t0 = Instant::now();
    let mut file = crate::io::gltf::load(&args.input)?;
    if args.integer {
        gltf_onto_grid(&mut file)?;
    }
    let mut times = Times {
        read: t0.elapsed(),
        ..Times::default()
    };
    let t0 = Instant::now();
    for p in &file.passed_through {
        eprintln!(
            "note: {}: {p} is not triangles: passed through unsimplified",
            args.input.display()
        );
    }
    let parts: Vec<Input> = file
        .primitives
        .iter()
        .map(|p| {
            (
                crate::io::gltf::label(p),
                MeshData {
                    positions: p.positions.clone(),
                    triangles: p.triangles.clone(),
                },
                texture_coordinates(&file, p),
                Some(shading::gltf(p)),
            )
        })
        .collect();
    times.welding = t0.elapsed();
    let normals: Vec<_> = file
        .primitives
        .iter()
        .map(super::attributes::gltf_normals)
        .collect();
    let mesh_of = |k: usize| file.primitives[k].mesh;
    let (done, results) = simplify_grouped(args, &parts, &normals, mesh_of, |g| {
        format!(
            "mesh {} ({} primitives)",
            mesh_of(g.members[0]),
            g.members.len()
        )
    })?;
    let gaps = gap_figures(&parts, &results, mesh_of, |m| format!("mesh {m}"));
    let t0 = Instant::now();
    let kept = if gltf_out(args) {
        if args.format == Some(super::OutputFormat::Glb) {
            // GLB whatever the name says.
            let (glb, _) = crate::io::gltf::write(&file, &results, true, "")
                .map_err(|e| anyhow!("{}: {e}", args.output.display()))?;
            std::fs::write(&args.output, glb)
                .map_err(|e| anyhow!("{}: cannot write: {e}", args.output.display()))?;
        } else {
            crate::io::gltf::save(&args.output, &file, &results)?;
        }
        format!(
            "glTF, {} triangle primitive(s), attributes {} kept per vertex",
            parts.len(),
            crate::io::gltf::attribute_summary(&file)
        )
    } else {
        let format = crate::io::output_format(&args.output, args.mesh_format())?;
        let written =
            crate::io::save_gltf_as(&args.output, format, &file, &results, args.keep_numbering)?;
        format!(
            "glTF to {}, {} triangle primitive(s), {written} written per vertex",
            format!("{format:?}").to_uppercase(),
            parts.len()
        )
    };
    times.write = t0.elapsed();
    let tin: usize = parts.iter().map(|(_, m, _, _)| m.triangles.len()).sum();
    let tout: usize = results.iter().map(Vec::len).sum();
    let head = format!(
        "simplify {} -> {} ({kept}): {tin} -> {tout} triangles\n",
        args.input.display(),
        args.output.display(),
    );
    finish(args, head, &done, &gaps, times)
}

/// Each part's result triangles, in its own numbering.
type PerPart = Vec<Vec<[u32; 3]>>;

/// [`simplify_parts`] on the runs [`groups`] makes of `parts` (`key_of`: the mesh a part
/// belongs to; `label`: a joined run's name), and each part's triangles in its own numbering.
fn simplify_grouped(
    args: &Args,
    parts: &[Input],
    normals: &[Option<Vec<[f32; 3]>>],
    key_of: impl Fn(usize) -> usize,
    label: impl Fn(&Group) -> String,
) -> Result<(Vec<Part>, PerPart)> {
    let groups = groups(args, parts, key_of);
    let (runs, run_normals): (Vec<Input>, Vec<_>) = groups
        .iter()
        .map(|g| join(label(g), g, parts, normals))
        .unzip();
    let done = simplify_parts(args, &runs, &run_normals)?;
    let mut results = vec![Vec::new(); parts.len()];
    for (g, d) in groups.iter().zip(&done) {
        for (&k, tris) in g.members.iter().zip(split(g, parts, &d.triangles)?) {
            results[k] = tris;
        }
    }
    Ok((done, results))
}

/// One mesh's [`gaps`] figure: its name, open edges in, out and new.
struct Gap {
    mesh: String,
    open: (usize, usize, usize),
}

/// [`gaps`] of every mesh (`key_of`) with more than one part, `name` naming it.
fn gap_figures(
    parts: &[Input],
    results: &[Vec<[u32; 3]>],
    key_of: impl Fn(usize) -> usize,
    name: impl Fn(usize) -> String,
) -> Vec<Gap> {
    let mut keys: Vec<usize> = (0..parts.len()).map(&key_of).collect();
    keys.dedup();
    let mut out = Vec::new();
    for key in keys {
        let members: Vec<usize> = (0..parts.len()).filter(|&k| key_of(k) == key).collect();
        if members.len() < 2 {
            continue;
        }
        let outputs: Vec<MeshData> = members
            .iter()
            .map(|&k| MeshData {
                positions: parts[k].1.positions.clone(),
                triangles: results[k].clone(),
            })
            .collect();
        let input: Vec<&MeshData> = members.iter().map(|&k| &parts[k].1).collect();
        out.push(Gap {
            mesh: name(key),
            open: gaps(&input, &outputs.iter().collect::<Vec<_>>()),
        });
    }
    out
}

/// The texture coordinates primitive `p`'s material reads (`TEXCOORD_n` of its
/// `baseColorTexture`, else `TEXCOORD_0`), one per vertex.
fn texture_coordinates(
    file: &crate::io::gltf::GltfFile,
    p: &crate::io::gltf::Primitive,
) -> Option<Vec<[f32; 2]>> {
    let name = crate::io::objattr::gltf_texcoord_name(file, p)?;
    let stream = p.attributes.iter().find(|s| s.semantic == name)?;
    (0..p.positions.len())
        .map(|i| crate::io::gltf::uv_of(stream, i).map(|uv| uv.map(|c| c as f32)))
        .collect()
}

/// Group `g`'s texture coordinates, one per vertex, when every vertex has one.
fn obj_texture_coordinates(file: &crate::io::objattr::ObjFile, g: usize) -> Option<Vec<[f32; 2]>> {
    file.groups[g]
        .vertices
        .iter()
        .map(|c| {
            let text = file.vt_text.get(c.1? as usize)?;
            let mut it = text.split_whitespace().map(str::parse::<f32>);
            Some([it.next()?.ok()?, it.next().unwrap_or(Ok(0.0)).ok()?])
        })
        .collect()
}

fn run_obj(args: &Args, bytes: &[u8], t0: Instant) -> Result<ExitCode> {
    let mut file =
        crate::io::objattr::parse(bytes).map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    if args.integer {
        obj_onto_grid(&mut file)?;
    }
    let mut times = Times {
        read: t0.elapsed(),
        ..Times::default()
    };
    let t0 = Instant::now();
    let parts: Vec<Input> = (0..file.groups.len())
        .filter(|&g| !file.groups[g].triangles.is_empty())
        .map(|g| {
            let name = file.groups[g]
                .material
                .as_deref()
                .map_or("no material".to_string(), |m| format!("material {m}"));
            (
                name,
                file.mesh(g),
                obj_texture_coordinates(&file, g),
                Some(shading::obj(&file, g)),
            )
        })
        .collect();
    times.welding = t0.elapsed();
    let normals: Vec<_> = (0..file.groups.len())
        .filter(|&g| !file.groups[g].triangles.is_empty())
        .map(|g| super::attributes::obj_normals(&file, g))
        .collect();
    // One OBJ is one mesh: all its groups in one run.
    let (done, kept) = simplify_grouped(
        args,
        &parts,
        &normals,
        |_| 0,
        |g| format!("all {} material groups", g.members.len()),
    )?;
    let gaps = gap_figures(&parts, &kept, |_| 0, |_| "the file".to_string());
    let t0 = Instant::now();
    let mut kept = kept.into_iter();
    let results: Vec<Vec<[u32; 3]>> = file
        .groups
        .iter()
        .map(|g| {
            if g.triangles.is_empty() {
                Vec::new()
            } else {
                kept.next().unwrap_or_default()
            }
        })
        .collect();
    let text = crate::io::objattr::write(&file, &results);
    std::fs::write(&args.output, text)
        .map_err(|e| anyhow!("{}: cannot write: {e}", args.output.display()))?;
    times.write = t0.elapsed();
    let tin: usize = parts.iter().map(|(_, m, _, _)| m.triangles.len()).sum();
    let tout: usize = results.iter().map(Vec::len).sum();
    let head = format!(
        "simplify {} -> {} (OBJ with {} texture coordinates, {} normals kept per vertex, {} \
         material group(s)): {tin} -> {tout} triangles\n",
        args.input.display(),
        args.output.display(),
        file.vt_text.len(),
        file.vn_text.len(),
        parts.len()
    );
    finish(args, head, &done, &gaps, times)
}
