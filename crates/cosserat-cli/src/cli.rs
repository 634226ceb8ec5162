//! The command-line grammar of `cosserat` (clap), in the library so that
//! tests can fuzz it without starting processes. `src/main.rs` runs it.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// `cosserat` and its options.
#[derive(Parser, Debug)]
#[command(
    name = "cosserat",
    version,
    about = "Statics and stability of slender elastic rods"
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
// The doc comments below are also clap's `--help` text, printed verbatim,
// so they keep TOML's table syntax (`[sweep]`) and values (`[5,0,0]`)
// unescaped, which rustdoc would otherwise take for intra-doc links.
#[derive(Subcommand, Debug)]
#[allow(rustdoc::broken_intra_doc_links)]
pub enum Command {
    /// Solve for the equilibrium of a rod problem.
    Solve {
        /// The problem file (TOML).
        problem: PathBuf,
        /// Write the solution to this HDF5 file (or, named *.vtp, as a
        /// VTK polyline for ParaView).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Override the solver method: "shooting", "multiple-shooting" or "collocation".
        #[arg(long)]
        method: Option<String>,
        /// Override any key of the problem file, e.g. --set loads.tip_force=[5,0,0].
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// Decide the stability of an equilibrium (lowest Hessian eigenvalues,
    /// Morse index), or the critical load of a fixed loaded shape.
    Stability {
        /// The problem file (TOML).
        problem: PathBuf,
        /// Write the analysis to this HDF5 file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Override any key of the problem file, e.g. --set stability.elements=400.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// Continue equilibria in a parameter ([continuation] table): branches,
    /// tracked Hessian eigenvalues, folds, branch points, branch switching.
    Continue {
        /// The problem file (TOML).
        problem: PathBuf,
        /// The HDF5 bifurcation diagram to write.
        #[arg(short, long)]
        output: PathBuf,
        /// Also draw the diagram (.png or .svg).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Go on with an interrupted run saved in the output file.
        #[arg(long)]
        resume: bool,
        /// Start from a point of this stored diagram (with --point), or
        /// from the equilibrium of this solve file (without --point),
        /// instead of the problem's own solve.
        #[arg(long, value_name = "DIAGRAM|SOLVE", conflicts_with = "resume")]
        from: Option<PathBuf>,
        /// The stored point: BRANCH/POINT, e.g. 1/10 or 1/last; or
        /// special/K to switch at the stored branch point K.
        #[arg(long, value_name = "B/I", requires = "from")]
        point: Option<String>,
        /// Follow the stored special point (--point special/K) in the
        /// second parameter of [continuation.curve] instead of switching:
        /// the output is a curve file.
        #[arg(long, requires = "point")]
        curve: bool,
        /// Override any key of the problem file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// The longest soft robotic arm of an [arm] table (paper Sec. 3–4).
    Optimize {
        /// The problem file (TOML).
        problem: PathBuf,
        /// Write the optimum to this HDF5 file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also continue the designed arm in its load from unloaded to the
        /// design load and write that diagram (HDF5, with a PNG beside it).
        #[arg(long)]
        loading_path: Option<PathBuf>,
        /// Also continue the designed arm along the control path, κ⁰ and
        /// the load raised together from the straight unloaded arm to the
        /// design, and write that diagram (HDF5, with a PNG beside it).
        #[arg(long)]
        control_path: Option<PathBuf>,
        /// Also continue the designed arm along the shape-holding control,
        /// κ⁰ = φ' − λ γ m̄ (the design shape an equilibrium at every load
        /// λ), and write that diagram (HDF5, with a PNG beside it).
        #[arg(long)]
        holding_path: Option<PathBuf>,
        /// Draw the study (.png or .svg): reach map, optimum 'P', the
        /// sample closest to a straight rod 'Q', their shapes (Fig. 5).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Go on with the interrupted search kept in the output file.
        #[arg(long)]
        resume: bool,
        /// Override any key of the problem file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// Run the problem's analysis at every point of its [sweep] grid, in
    /// parallel, resumable and shardable (one HDF5 file per shard).
    Sweep {
        /// The problem file (TOML) with a [sweep] table.
        problem: PathBuf,
        /// The HDF5 results (also the checkpoint of a running sweep).
        #[arg(short, long)]
        output: PathBuf,
        /// Compute shard i of n (0 ≤ i < n): every n-th line of the grid.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
        /// Worker threads (default: all cores; at most 4 per core).
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
        threads: Option<u16>,
        /// Go on with an interrupted or killed sweep saved in the output file.
        #[arg(long)]
        resume: bool,
        /// Also draw the sweep (.png or .svg): contour maps or reach envelopes.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Override any key of the problem file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// Join the shard files of one sweep into one file.
    Merge {
        /// The shard files.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// The joined file.
        #[arg(short, long)]
        output: PathBuf,
        /// Also draw the joined sweep (.png or .svg).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Overwrite an existing output file.
        #[arg(long)]
        force: bool,
    },
    /// Export the rod shapes of a result file for ParaView: an
    /// equilibrium as one polyline with its fields, a diagram as one time
    /// step per continuation point (VTK .pvd of .vtp files, or XDMF
    /// referring into the HDF5 file).
    Export(crate::export_command::ExportArgs),
    /// Draw a bifurcation diagram file.
    Plot {
        /// The HDF5 diagram from `cosserat continue`.
        diagram: PathBuf,
        /// The figure (.png or .svg).
        #[arg(short, long, default_value = "diagram.png")]
        output: PathBuf,
        /// Vertical axis: tip_x, tip_y, tip_z, norm or tip_angle.
        #[arg(long, default_value = "tip_x")]
        measure: String,
        /// Overwrite an existing figure.
        #[arg(long)]
        force: bool,
    },
    /// Check the stored energy of a problem: each derivative against a
    /// difference of the quantity below it, symmetry, convexity and the
    /// planar claim, at sampled strains and along the solution.
    CheckEnergy {
        /// The problem file (TOML).
        problem: PathBuf,
        /// Override any key of the problem file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Benchmarks: `cosserat bench work-precision [-o DIR]`,
    /// `cosserat bench solve|stability|continue|optimize PROBLEM [--set
    /// KEY=VALUE ...] [--repeat N] [--csv FILE]` (docs/performance.md).
    Bench {
        /// Which benchmark.
        #[command(subcommand)]
        which: crate::bench::BenchCommand,
    },
    /// Classical benchmarks against every method, with a Markdown report.
    Validate(crate::validate::ValidateArgs),
}
