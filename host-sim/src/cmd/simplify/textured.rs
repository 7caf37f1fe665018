//! `host-sim simplify` on meshes with vertex attributes: glTF/GLB ([`crate::io::gltf`]), OBJ
//! with `vt`/`vn` ([`crate::io::objattr`]) and PLY with vertex properties besides x, y, z
//! ([`crate::io::plyattr`]).
//!
//! Each part (a glTF triangle primitive, an OBJ material group) is simplified on its own with
//! the same configuration; `--target-triangles N` is shared among the parts in proportion to
//! their triangles. The validity check and the Metro error run per part, in the part's own
//! coordinates (node transforms are not applied); the result is valid when every part is.
//! The attributes of every kept vertex are those of an input vertex, bit for bit, because the
//! library's subset placement only moves triangles. Optimal placement moves vertices without
//! interpolating attributes, so `--placement optimal` is refused here.

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Result};
use tinydecimate::{Config, Report, Target};

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
) -> Result<(Vec<[u32; 3]>, Report)> {
    let stored = args.quadric == QuadricArg::Stored;
    let placement = stored.then_some(tinydecimate::cost::Placement::Subset);
    let run = crate::simplify::Run {
        operator: args.operator,
        placement,
        bounded: args.max_error.is_some(),
        weld: args.seams == super::SeamsArg::Weld,
        ..Default::default()
    };
    let (out, report, _) =
        crate::simplify::simplify_with_attributes(mesh, config, &run, attributes)?;
    Ok((out.triangles, report))
}

/// Runs `simplify` here when the input or output is glTF, or the input is an OBJ with texture
/// coordinates or normals written to OBJ; `None` leaves the run to the plain path.
pub fn run_if_attributes(args: &Args) -> Result<Option<ExitCode>> {
    let (i, o) = (&args.input, &args.output);
    let gi = crate::io::gltf::is_gltf_path(i);
    let go = crate::io::gltf::is_gltf_path(o);
    if gi || go {
        if !(gi && go) {
            bail!(
                "glTF is read and written only as glTF: give both {} and {} a .gltf or .glb \
                 extension",
                i.display(),
                o.display()
            );
        }
        refuse_optimal(args)?;
        // The output is checked before the long work, as on the plain path.
        if o.is_dir() {
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
        && crate::io::check_writable(o, args.format).is_ok()
        && args.format.is_none_or(|f| f == crate::io::Format::Obj)
        && !args.keep_numbering
    {
        let bytes = std::fs::read(i).map_err(|e| anyhow!("{}: cannot read: {e}", i.display()))?;
        if crate::io::objattr::has_attributes(&bytes) {
            refuse_optimal(args)?;
            return run_obj(args, &bytes).map(Some);
        }
    }
    let is_ply = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("ply"))
    };
    if is_ply(i)
        && is_ply(o)
        && crate::io::check_writable(o, args.format).is_ok()
        && args.format.is_none_or(|f| f == crate::io::Format::Ply)
        && !args.keep_numbering
    {
        let bytes = std::fs::read(i).map_err(|e| anyhow!("{}: cannot read: {e}", i.display()))?;
        let extra = crate::io::plyattr::extra_properties(&bytes);
        if !extra.is_empty() {
            refuse_optimal(args)?;
            return run_ply(args, &bytes, &extra).map(Some);
        }
    }
    Ok(None)
}

fn run_ply(args: &Args, bytes: &[u8], extra: &[String]) -> Result<ExitCode> {
    let file =
        crate::io::plyattr::parse(bytes).map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    let parts = vec![("vertex element".to_string(), file.mesh.clone(), None)];
    let done = simplify_parts(args, &parts, &[])?;
    let out = crate::io::plyattr::write(&file, &done[0].triangles)
        .map_err(|e| anyhow!("{}: {e}", args.output.display()))?;
    std::fs::write(&args.output, out)
        .map_err(|e| anyhow!("{}: cannot write: {e}", args.output.display()))?;
    let head = format!(
        "simplify {} -> {} (PLY, vertex properties {} kept per vertex): {} -> {} triangles\n",
        args.input.display(),
        args.output.display(),
        extra.join(", "),
        file.mesh.triangles.len(),
        done[0].triangles.len()
    );
    finish(args, head, &done)
}

fn refuse_optimal(args: &Args) -> Result<()> {
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
    triangles: Vec<[u32; 3]>,
    /// The part's target, and whether it stopped short of it.
    target: usize,
    short: bool,
    line: String,
    valid: bool,
    json: serde_json::Value,
}

/// One part to simplify: its label, its mesh and, when it has them, the texture coordinates
/// its material reads (one per vertex), for the UV stretch figure.
type Input = (String, MeshData, Option<Vec<[f32; 2]>>);

/// Simplifies each mesh of `parts` with `args`' configuration; `normals` (per part, may be
/// shorter) are only read by `--attribute-weights`.
fn simplify_parts(
    args: &Args,
    parts: &[Input],
    normals: &[Option<Vec<[f32; 3]>>],
) -> Result<Vec<Part>> {
    let total: usize = parts.iter().map(|(_, m, _)| m.triangles.len()).sum();
    let mut out = Vec::new();
    for (k, (label, mesh, uvs)) in parts.iter().enumerate() {
        let mut config = args.config();
        if let Some(n) = args.target_triangles {
            let share = (n as f64 * mesh.triangles.len() as f64 / total.max(1) as f64).round();
            config = config.with_target(Target::Triangles(share as usize));
        }
        if let Some(e) = args.max_error {
            config = config.with_max_error(e.distance(&mesh.positions));
        }
        config = config.with_error_limit(args.error_limit().distance(&mesh.positions));
        config
            .validate()
            .map_err(|e| anyhow!("configuration: {e}"))?;
        let attributes = super::attributes::for_part(
            args,
            label,
            mesh.positions.len(),
            uvs.as_deref(),
            normals.get(k).and_then(Option::as_deref),
        )?;
        let (tris, report) = run_library(mesh, &config, args, attributes.as_ref())
            .map_err(|e| anyhow!("{label}: {e}"))?;
        let result = MeshData {
            positions: mesh.positions.clone(),
            triangles: tris.clone(),
        };
        let mut line = format!(
            "  {label}: {} -> {} triangles (target {}, stop {:?}){}",
            report.triangles_in,
            report.triangles_out,
            report.target_triangles,
            report.stop,
            if parts.len() == 1 {
                format!("\n{}", crate::simplify::format_report(&report))
            } else {
                String::new()
            }
        );
        // Why it stopped short, per part; the fallback is for the whole file (`finish`).
        let advice = super::advice_for(args, &report).map(|(outcome, mut a)| {
            a.fallback = None;
            a.fallback_then_collapse = None;
            let _ = write!(line, "\n{}", a.text(&outcome, "    ").trim_end());
            a
        });
        let mut valid = true;
        let mut json = serde_json::json!({
            "part": label,
            "report": crate::simplify::report_json(&report),
            "advice": advice,
        });
        if !args.no_measure {
            let weld = args.seams == super::SeamsArg::Weld;
            let v = crate::check::compare_opts(mesh, &result, false, weld);
            valid = v.is_valid();
            let opts = crate::metro::MetroOptions {
                samples_per_triangle: args.samples_per_triangle,
                progress: false,
                ..Default::default()
            };
            let m = crate::metro::metro(mesh, &result, &opts);
            let _ = write!(
                line,
                ", {}, Metro max {:.4} % mean {:.4} % of the diagonal",
                if valid { "valid" } else { "NOT valid" },
                m.hausdorff_pct,
                m.symmetric_mean_pct
            );
            if !valid {
                for d in &v.defects {
                    let _ = write!(line, "\n    {d}");
                }
            }
            json["valid"] = serde_json::Value::Bool(valid);
            json["defects"] =
                serde_json::json!(v.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>());
            json["metro"] = serde_json::to_value(&m)?;
            if let Some(uvs) = uvs {
                let _ = write!(
                    line,
                    "{}{}",
                    uv_stretch(mesh, uvs, &result, &mut json),
                    super::attributes::meshopt_reference(
                        mesh,
                        uvs,
                        &result,
                        &attributes,
                        &mut json
                    )
                );
            }
        }
        out.push(Part {
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

/// The UV stretch of the input, the result and meshoptimizer's `simplify` at the result's
/// triangle count (see [`crate::uvstretch`]), as text for the part's line and into `json`.
fn uv_stretch(
    mesh: &MeshData,
    uvs: &[[f32; 2]],
    result: &MeshData,
    json: &mut serde_json::Value,
) -> String {
    let stretch = |t: &[[u32; 3]]| crate::uvstretch::l2_stretch(&mesh.positions, uvs, t);
    let (Some(input), Some(ours)) = (stretch(&mesh.triangles), stretch(&result.triangles)) else {
        return String::new();
    };
    let (anchor, _, _) = crate::bench::meshopt::meshopt_simplify(mesh, result.triangles.len());
    let theirs = stretch(&anchor.triangles);
    let diag = mesh.bbox_diagonal().max(f64::MIN_POSITIVE);
    let deviation = |t: &[[u32; 3]]| {
        crate::uvstretch::texture_deviation(&mesh.positions, uvs, &mesh.triangles, t)
            .map(|(mean, max, lost)| (100.0 * mean / diag, 100.0 * max / diag, lost))
    };
    let (dev_ours, dev_theirs) = (deviation(&result.triangles), deviation(&anchor.triangles));
    json["uv_stretch"] = serde_json::json!({
        "input": input,
        "result": ours,
        "meshopt": theirs,
        "meshopt_triangles": anchor.triangles.len(),
        "texture_deviation_pct": dev_ours.map(|d| [d.0, d.1]),
        "texture_samples_lost": dev_ours.map(|d| d.2),
        "meshopt_texture_deviation_pct": dev_theirs.map(|d| [d.0, d.1]),
        "meshopt_texture_samples_lost": dev_theirs.map(|d| d.2),
    });
    let dev = |d: Option<(f64, f64, usize)>| {
        d.map_or(String::new(), |(mean, max, lost)| {
            format!(", texture deviation mean {mean:.4} % max {max:.4} %, {lost} samples lost")
        })
    };
    format!(
        "\n    UV stretch {ours:.4} (input {input:.4}){}\n    meshoptimizer at {} triangles: UV \
         stretch {}{}",
        dev(dev_ours),
        anchor.triangles.len(),
        theirs.map_or("-".into(), |t| format!("{t:.4}")),
        dev(dev_theirs)
    )
}

fn finish(args: &Args, head: String, parts: &[Part]) -> Result<ExitCode> {
    let valid = parts.iter().all(|p| p.valid);
    // A part stopped short: clustering reaches the file's count (on positions only; it reads
    // no glTF).
    let fallback =
        (parts.iter().any(|p| p.short) && !crate::gltf::is_gltf_path(&args.input)).then(|| {
            super::advice::fallbacks(
                &args.input.display().to_string(),
                &args.output.display().to_string(),
                parts.iter().map(|p| p.target).sum(),
            )
        });
    if args.json {
        let mut j = serde_json::json!({
            "input": args.input.display().to_string(),
            "output": args.output.display().to_string(),
            "parts": parts.iter().map(|p| p.json.clone()).collect::<Vec<_>>(),
            "triangles_out": parts.iter().map(|p| p.triangles.len()).sum::<usize>(),
            "valid": valid,
            "fallback": fallback.as_ref().map(|f| [&f.0, &f.1]),
        });
        if let [p] = parts {
            // One part: its report where the plain path puts it.
            j["report"] = p.json["report"].clone();
        }
        crate::outln!("{}", serde_json::to_string_pretty(&j)?);
    } else {
        let mut text = head;
        for p in parts {
            let _ = writeln!(text, "{}", p.line);
        }
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
    let file = crate::io::gltf::load(&args.input)?;
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
            )
        })
        .collect();
    let normals: Vec<_> = file
        .primitives
        .iter()
        .map(super::attributes::gltf_normals)
        .collect();
    let done = simplify_parts(args, &parts, &normals)?;
    let results: Vec<Vec<[u32; 3]>> = done.iter().map(|p| p.triangles.clone()).collect();
    crate::io::gltf::save(&args.output, &file, &results)?;
    let tin: usize = parts.iter().map(|(_, m, _)| m.triangles.len()).sum();
    let tout: usize = results.iter().map(Vec::len).sum();
    let head = format!(
        "simplify {} -> {} (glTF, {} triangle primitive(s), attributes {} kept per vertex): \
         {tin} -> {tout} triangles\n",
        args.input.display(),
        args.output.display(),
        parts.len(),
        crate::io::gltf::attribute_summary(&file)
    );
    finish(args, head, &done)
}

/// The texture coordinates primitive `p`'s material reads (`TEXCOORD_n` of its
/// `baseColorTexture`, else `TEXCOORD_0`), one per vertex.
fn texture_coordinates(
    file: &crate::io::gltf::GltfFile,
    p: &crate::io::gltf::Primitive,
) -> Option<Vec<[f32; 2]>> {
    let material = &file.json["meshes"][p.mesh]["primitives"][p.index]["material"];
    let n = material
        .as_u64()
        .and_then(|m| {
            file.json["materials"][m as usize]["pbrMetallicRoughness"]["baseColorTexture"]
                ["texCoord"]
                .as_u64()
        })
        .unwrap_or(0);
    let name = format!("TEXCOORD_{n}");
    let stream = p.attributes.iter().find(|s| s.semantic == name)?;
    (0..p.positions.len())
        .map(|i| crate::texrender::uv_of(stream, i).map(|uv| uv.map(|c| c as f32)))
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

fn run_obj(args: &Args, bytes: &[u8]) -> Result<ExitCode> {
    let file =
        crate::io::objattr::parse(bytes).map_err(|e| anyhow!("{}: {e}", args.input.display()))?;
    let parts: Vec<Input> = (0..file.groups.len())
        .filter(|&g| !file.groups[g].triangles.is_empty())
        .map(|g| {
            let name = file.groups[g]
                .material
                .as_deref()
                .map_or("no material".to_string(), |m| format!("material {m}"));
            (name, file.mesh(g), obj_texture_coordinates(&file, g))
        })
        .collect();
    let normals: Vec<_> = (0..file.groups.len())
        .filter(|&g| !file.groups[g].triangles.is_empty())
        .map(|g| super::attributes::obj_normals(&file, g))
        .collect();
    let done = simplify_parts(args, &parts, &normals)?;
    let mut results = Vec::new();
    let mut k = 0;
    for g in &file.groups {
        if g.triangles.is_empty() {
            results.push(Vec::new());
        } else {
            results.push(done[k].triangles.clone());
            k += 1;
        }
    }
    let text = crate::io::objattr::write(&file, &results);
    std::fs::write(&args.output, text)
        .map_err(|e| anyhow!("{}: cannot write: {e}", args.output.display()))?;
    let tin: usize = parts.iter().map(|(_, m, _)| m.triangles.len()).sum();
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
    finish(args, head, &done)
}
