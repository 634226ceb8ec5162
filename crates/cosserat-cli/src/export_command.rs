//! `cosserat export FILE.h5 --format vtk|xdmf [-o OUT] [--branch B]`: the
//! rod shapes of a result file for ParaView. An equilibrium becomes one
//! polyline with its fields; a diagram one time step per continuation
//! point, so ParaView animates the branch; an arm study one step per
//! stored design.
//!
//! VTK: a `.vtp` file for one shape, or a `.pvd` collection with one
//! `.vtp` per shape beside it (`OUT_0000.vtp`, …). XDMF: one `.xmf2` file
//! whose arrays are references into the HDF5 file itself (keep the two
//! together). The extension `.xmf2` makes ParaView open it with its XDMF 2
//! reader ("XDMF Reader"), which reads the hyperslab picking each diagram
//! point's row; ParaView's Xdmf3 readers ask an array for its type before
//! reading it and so skip every hyperslab (tested with ParaView 5.11). The time of a step is the continuation parameter where it is
//! strictly monotone along the exported branch, else the point index;
//! the files say which (a comment in the `.pvd`, an `Information` element
//! in the `.xmf`), and so does the command's report.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use cosserat::output::target::{claim, ensure_replaceable, replace_atomically, temporary_path};
use cosserat::output::vtk::{self, PointField, Polyline, Step};
use cosserat::output::xdmf::{self, Attribute, Grid, Stored, Values};

use crate::exit::{fail, BAD_INPUT, OUTPUT};
use crate::shape_file::{read_shapes, Array, Branch, FileKind, Frame, ShapeFile};

/// The file format written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// VTK XML PolyData (`.vtp`), several shapes as a `.pvd` collection.
    Vtk,
    /// XDMF (`.xmf`) referring into the HDF5 file.
    Xdmf,
}

/// What `cosserat export` was asked (its command-line arguments).
#[derive(Debug, Clone, clap::Args)]
pub struct ExportArgs {
    /// The HDF5 result file (solve, stability, continue or optimize).
    #[arg(value_name = "FILE")]
    pub input: PathBuf,
    /// vtk (.vtp, or .pvd with one .vtp per shape) or xdmf (.xmf2).
    #[arg(long, value_enum)]
    pub format: Format,
    /// The file to write (default: FILE with .vtp, .pvd or .xmf2).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Only this branch of a diagram (its time is then the parameter
    /// where that is monotone along the branch).
    #[arg(long)]
    pub branch: Option<usize>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// The shapes to export, with the time of each and what the time means.
struct Timeline<'a> {
    frames: Vec<&'a Frame>,
    times: Vec<f64>,
    note: String,
}

/// `cosserat export`; returns the exit code.
pub fn run_export(args: &ExportArgs) -> ExitCode {
    let file = match read_shapes(&args.input) {
        Ok(f) => f,
        Err(e) => return fail(BAD_INPUT, e),
    };
    let timeline = match timeline(&file, args.branch) {
        Ok(t) => t,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", args.input.display())),
    };
    if timeline.frames.is_empty() {
        return fail(
            BAD_INPUT,
            format!(
                "{}: the file holds no point to export",
                args.input.display()
            ),
        );
    }
    let arc = arc_lengths(&file, &timeline.frames);
    println!("input     {}", args.input.display());
    println!("shapes    {}", timeline.frames.len());
    println!("time      {}", timeline.note);
    match args.format {
        Format::Vtk => export_vtk(args, &timeline, &arc),
        Format::Xdmf => export_xdmf(args, &timeline, &arc),
    }
}

/// The frames to export in order of increasing time.
fn timeline(file: &ShapeFile, branch: Option<usize>) -> Result<Timeline<'_>, String> {
    match file.kind {
        FileKind::Equilibrium | FileKind::ArmStudy if branch.is_some() => {
            return Err("--branch applies to diagrams (continue -o) only".into())
        }
        FileKind::Equilibrium => {
            return Ok(Timeline {
                frames: file.frames.iter().collect(),
                times: vec![0.0],
                note: "one equilibrium, at time 0".into(),
            })
        }
        FileKind::ArmStudy => {
            let labels: Vec<&str> = file.frames.iter().map(|f| f.label.as_str()).collect();
            return Ok(Timeline {
                frames: file.frames.iter().collect(),
                times: (0..labels.len()).map(|i| i as f64).collect(),
                note: format!(
                    "design index: {} (arm-study coordinates, scaled by the square root of the load factor)",
                    labels.join(", ")
                ),
            });
        }
        FileKind::Diagram => {}
    }
    let count = file.branches.len();
    let chosen = match branch {
        Some(b) if b >= count => {
            return Err(format!(
                "--branch {b}: the diagram has {count} branches (0 to {})",
                count.saturating_sub(1)
            ))
        }
        Some(b) => Some(b),
        None if count == 1 => Some(0),
        None => None,
    };
    let Some(b) = chosen else {
        return Ok(Timeline {
            frames: file.frames.iter().collect(),
            times: (0..file.frames.len()).map(|i| i as f64).collect(),
            note: format!(
                "point index over all {count} branches in order; --branch B animates one \
                 branch in its parameter"
            ),
        });
    };
    Ok(branch_timeline(file, b))
}

/// The points of branch `b`: in the order and at the values of the
/// parameter where it is strictly monotone along the branch, else by
/// index.
fn branch_timeline(file: &ShapeFile, b: usize) -> Timeline<'_> {
    let mut frames: Vec<&Frame> = file.frames.iter().filter(|f| f.branch == Some(b)).collect();
    let name = file.branches[b]
        .parameter_name
        .clone()
        .unwrap_or_else(|| "the parameter".into());
    let p: Vec<f64> = frames.iter().filter_map(|f| f.parameter).collect();
    let rising = p.len() > 1 && p.windows(2).all(|w| w[1] > w[0]);
    let falling = p.len() > 1 && p.windows(2).all(|w| w[1] < w[0]);
    if rising || falling {
        if falling {
            frames.reverse();
        }
        let times = frames.iter().filter_map(|f| f.parameter).collect();
        return Timeline {
            frames,
            times,
            note: format!("the continuation parameter {name} (monotone along branch {b})"),
        };
    }
    Timeline {
        times: (0..frames.len()).map(|i| i as f64).collect(),
        frames,
        note: format!("point index along branch {b} ({name} is not monotone along it)"),
    }
}

/// The arc length s of each diagram frame's equally spaced points, where
/// the rod length at the point is known: the stored problem reread with
/// the branch's held keys and its key at the point's value. `None` where
/// it is not (a path of `optimize`, whose rod is the design's, or a shape
/// whose polyline length is implausible for that length).
fn arc_lengths(file: &ShapeFile, frames: &[&Frame]) -> Vec<Option<Vec<f64>>> {
    let mut cache: Vec<Option<(Option<f64>, Option<f64>)>> = vec![None; file.branches.len()];
    frames
        .iter()
        .map(|f| {
            if !f.equally_spaced {
                return None;
            }
            let (b, p) = (f.branch?, f.parameter?);
            let branch = file.branches.get(b)?;
            let varies = branch.parameter_name.as_deref() == Some("rod.length");
            let length = match cache[b] {
                Some((key, l)) if !varies || key == Some(p) => l,
                _ => {
                    let l = rod_length(&file.problem, branch, p);
                    cache[b] = Some((Some(p), l));
                    l
                }
            }?;
            let n = f.points.points();
            let chord = polyline_length(&f.points.values);
            // Chords are shorter than the arc, by well under half even for
            // a coiled rod at 21 points; a length far off is not this rod's.
            if !(chord > 0.5 * length && chord < 1.5 * length) && n > 1 {
                return None;
            }
            let last = (n.max(2) - 1) as f64;
            Some((0..n).map(|k| length * k as f64 / last).collect())
        })
        .collect()
}

/// The rod length of the stored problem at a point of `branch`.
fn rod_length(problem: &str, branch: &Branch, value: f64) -> Option<f64> {
    use cosserat::continuation::Parameter;
    let mut sets: Vec<String> = branch
        .held
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let key = branch.parameter_name.as_deref()?;
    if Parameter::from_key(key).is_none_or(Parameter::is_file_key) {
        sets.push(format!("{key}={value:e}"));
    }
    crate::energies::read_problem_text(problem, &sets)
        .ok()
        .map(|p| p.rod.length())
}

fn polyline_length(xyz: &[f64]) -> f64 {
    xyz.chunks_exact(3)
        .collect::<Vec<_>>()
        .windows(2)
        .map(|w| {
            let d: f64 = (0..3).map(|i| (w[1][i] - w[0][i]).powi(2)).sum();
            d.sqrt()
        })
        .sum()
}

/// The fraction s/L of each equally spaced point.
fn fraction(n: usize) -> Vec<f64> {
    let last = (n.max(2) - 1) as f64;
    (0..n).map(|k| k as f64 / last).collect()
}

/// The output path: the given one, or the input's with the extension of
/// the format (`.vtp` for one VTK shape, `.pvd` for several).
fn output_path(args: &ExportArgs, shapes: usize) -> PathBuf {
    let ext = match args.format {
        Format::Vtk if shapes == 1 => "vtp",
        Format::Vtk => "pvd",
        Format::Xdmf => "xmf2",
    };
    args.output
        .clone()
        .unwrap_or_else(|| args.input.with_extension(ext))
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// `OUT_0000.vtp`, … beside a `.pvd`.
fn frame_paths(pvd: &Path, count: usize) -> Vec<PathBuf> {
    let stem = pvd
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let width = count.saturating_sub(1).to_string().len().max(4);
    (0..count)
        .map(|k| pvd.with_file_name(format!("{stem}_{k:0width$}.vtp")))
        .collect()
}

/// The VTK polyline of a frame with its arrays and, for a diagram point,
/// its parameter, Morse index and stability as field data.
fn polyline(frame: &Frame, s: Option<&Vec<f64>>) -> Result<Polyline, vtk::VtkError> {
    let points: Vec<[f64; 3]> = frame
        .points
        .values
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let mut fields = vec![];
    if frame.equally_spaced {
        if let Some(s) = s.filter(|_| !frame.has_field("s")) {
            fields.push(PointField::new("s", 1, s.clone())?);
        }
        fields.push(PointField::new(
            "s_over_L",
            1,
            fraction(frame.points.points()),
        )?);
    }
    for f in &frame.fields {
        let k = f.array.values.len() / frame.points.points().max(1);
        fields.push(PointField::new(f.name, k, f.array.values.clone())?);
    }
    let mut rod = Polyline::new(points, fields)?;
    let tags = [
        ("parameter", frame.parameter),
        ("morse_index", frame.morse_index.map(|m| m as f64)),
        ("stable", frame.stable.map(|s| f64::from(u8::from(s)))),
        ("branch", frame.branch.map(|b| b as f64)),
    ];
    for (name, value) in tags {
        if let Some(v) = value {
            rod = rod.with_tag(name, v)?;
        }
    }
    Ok(rod)
}

/// Fails unless every path of a collection may be written: not the input,
/// a regular file or absent, and absent unless `--force`.
fn check_frames(paths: &[PathBuf], input: &Path, force: bool) -> Result<(), String> {
    let same = |a: &Path, b: &Path| match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    };
    for p in paths {
        if same(p, input) {
            return Err(format!("{} is the input of this command", p.display()));
        }
        ensure_replaceable(p).map_err(|e| e.to_string())?;
        if p.exists() && !force {
            return Err(format!(
                "{} exists; pass --force to overwrite it",
                p.display()
            ));
        }
    }
    Ok(())
}

fn write_text(path: &Path, text: &str) -> Result<(), String> {
    replace_atomically(path, |tmp| std::fs::write(tmp, text))
}

fn export_vtk(args: &ExportArgs, t: &Timeline, arc: &[Option<Vec<f64>>]) -> ExitCode {
    let out = output_path(args, t.frames.len());
    let collection = match extension(&out).as_str() {
        "vtp" if t.frames.len() == 1 => false,
        "vtp" => {
            return fail(
                BAD_INPUT,
                format!(
                    "{} holds {} shapes; write them as a collection, -o NAME.pvd \
                     (or pick one branch with --branch)",
                    args.input.display(),
                    t.frames.len()
                ),
            )
        }
        "pvd" => true,
        _ => {
            return fail(
                BAD_INPUT,
                format!("{}: VTK output is a .vtp or .pvd file", out.display()),
            )
        }
    };
    let rods: Result<Vec<Polyline>, _> = t
        .frames
        .iter()
        .zip(arc)
        .map(|(f, s)| polyline(f, s.as_ref()))
        .collect();
    let rods = match rods {
        Ok(r) => r,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", args.input.display())),
    };
    let _claim = match claim(&out, &[args.input.as_path()], args.force) {
        Ok(c) => crate::solve_command::hold(c),
        Err(e) => return fail(BAD_INPUT, e),
    };
    if !collection {
        if let Err(e) = write_text(&out, &vtk::polydata(&rods[0])) {
            return fail(OUTPUT, e);
        }
        println!("written   {}", out.display());
        return ExitCode::SUCCESS;
    }
    let paths = frame_paths(&out, rods.len());
    // Every name is checked before the first file is written.
    let steps: Result<Vec<Step>, String> = paths
        .iter()
        .zip(&t.times)
        .map(|(path, &time)| {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
            Step::new(time, &name.unwrap_or_default()).map_err(|e| e.to_string())
        })
        .collect();
    let steps = match steps.and_then(|s| check_frames(&paths, &args.input, args.force).map(|()| s))
    {
        Ok(s) => s,
        Err(e) => return fail(BAD_INPUT, e),
    };
    for (rod, path) in rods.iter().zip(&paths) {
        crate::signals::litter(temporary_path(path));
        if let Err(e) = write_text(path, &vtk::polydata(rod)) {
            return fail(OUTPUT, e);
        }
    }
    let note = format!("timestep: {}", t.note);
    if let Err(e) = write_text(&out, &vtk::collection(&steps, &note)) {
        return fail(OUTPUT, e);
    }
    println!(
        "written   {} and {} .vtp files beside it",
        out.display(),
        paths.len()
    );
    ExitCode::SUCCESS
}

/// How the `.xmf` file names the HDF5 file: by its name when both are in
/// one directory (so the pair can move together), else by its absolute
/// path.
fn reference(input: &Path, output: &Path) -> Result<String, String> {
    let full = std::fs::canonicalize(input).map_err(|e| format!("{}: {e}", input.display()))?;
    let dir = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let same_dir = std::fs::canonicalize(&dir)
        .ok()
        .is_some_and(|d| full.parent() == Some(d.as_path()));
    Ok(match (same_dir, full.file_name()) {
        (true, Some(name)) => name.to_string_lossy().into_owned(),
        _ => full.to_string_lossy().into_owned(),
    })
}

fn stored(file: &str, a: &Array) -> Result<Stored, xdmf::XdmfError> {
    Stored::new(file, &a.dataset, &a.dims, a.row)
}

/// The XDMF grid of a frame: points and fields from the HDF5 file, the
/// arc length of a diagram's shape points inline.
fn grid(file: &str, frame: &Frame, time: f64, s: Option<&Vec<f64>>) -> Result<Grid, String> {
    let mut attributes = vec![];
    if frame.equally_spaced {
        if let Some(s) = s.filter(|_| !frame.has_field("s")) {
            attributes
                .push(Attribute::new("s", Values::Inline(s.clone())).map_err(|e| e.to_string())?);
        }
        let f = fraction(frame.points.points());
        attributes.push(Attribute::new("s_over_L", Values::Inline(f)).map_err(|e| e.to_string())?);
    }
    for f in &frame.fields {
        let values = Values::Stored(stored(file, &f.array).map_err(|e| e.to_string())?);
        attributes.push(Attribute::new(f.name, values).map_err(|e| e.to_string())?);
    }
    let points = stored(file, &frame.points).map_err(|e| e.to_string())?;
    Grid::new(&frame.label, time, points, attributes).map_err(|e| e.to_string())
}

fn export_xdmf(args: &ExportArgs, t: &Timeline, arc: &[Option<Vec<f64>>]) -> ExitCode {
    let out = output_path(args, t.frames.len());
    let ext = extension(&out);
    if !matches!(ext.as_str(), "xmf2" | "xdmf2" | "xmf" | "xdmf") {
        return fail(
            BAD_INPUT,
            format!(
                "{}: XDMF output is a .xmf2 file (or .xdmf2, .xmf, .xdmf)",
                out.display()
            ),
        );
    }
    let _claim = match claim(&out, &[args.input.as_path()], args.force) {
        Ok(c) => crate::solve_command::hold(c),
        Err(e) => return fail(BAD_INPUT, e),
    };
    let text = reference(&args.input, &out).and_then(|h5| {
        let grids: Result<Vec<Grid>, String> = t
            .frames
            .iter()
            .zip(&t.times)
            .zip(arc)
            .map(|((f, &time), s)| grid(&h5, f, time, s.as_ref()))
            .collect();
        let note = format!("time = {}", t.note);
        xdmf::temporal_collection(&grids?, &note).map_err(|e| e.to_string())
    });
    let text = match text {
        Ok(t) => t,
        Err(e) => return fail(BAD_INPUT, format!("{}: {e}", args.input.display())),
    };
    if let Err(e) = write_text(&out, &text) {
        return fail(OUTPUT, e);
    }
    println!(
        "written   {} (its arrays are read from {}: keep the two together)",
        out.display(),
        args.input.display()
    );
    let slabs = t.frames.iter().any(|f| f.points.row.is_some());
    if slabs && !ext.ends_with('2') {
        println!(
            "note      open it in ParaView with the \"XDMF Reader\": the Xdmf3 readers \
             do not read the hyperslabs that pick each point's shape (.xmf2 selects it)"
        );
    }
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collection_frames_are_numbered_beside_the_collection() {
        let p = frame_paths(Path::new("dir/shape.pvd"), 3);
        assert_eq!(p[2], Path::new("dir/shape_0002.vtp"));
        assert_eq!(
            frame_paths(Path::new("a.pvd"), 12345)[0],
            Path::new("a_00000.vtp")
        );
    }

    #[test]
    fn the_fraction_spans_zero_to_one() {
        assert_eq!(fraction(3), vec![0.0, 0.5, 1.0]);
        assert!((polyline_length(&[0.0, 0.0, 0.0, 3.0, 4.0, 0.0]) - 5.0).abs() < 1e-15);
    }
}
