//! Command-line front end (clap). Errors print as one line: `galvoplan: error: FILE: what`.

mod bench;
mod cap;
mod hatch_bench;
mod linuxcnc;
mod plan;
mod progress;
mod tsp;

use anyhow::Result;
use clap::{Args, Parser, Subcommand, ValueEnum};
use galvoplan::document::FillShapes;
use galvoplan::document::{
    Algo, CostModel, FieldsMode, MachineProfile, MotionMode, PenLibrary, RouteGaSettings,
    SolverSettings, StageRouteKind, VertexMode,
};
use galvoplan::document::{CodeSpec, DataTable, Numbering, Serial, Stamp, Tray, TraySettings};
use galvoplan::geom::seam::SeamForm;
use galvoplan::hatch::{HatchSettings, OutlineMode};
use galvoplan::import::{HiddenLayers, ImportOptions, Place};
use std::path::PathBuf;

/// CAM for redundant laser-marking machines (galvo scanner on an XY base stage).
#[derive(Parser, Debug)]
#[command(name = "galvoplan", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// With no subcommand: an SVG, DXF or project file to open in the GUI.
    file: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Plan one job: SVG or DXF in, G-code (and report, preview) out.
    Plan(PlanArgs),
    /// Run the pipeline over SVG files or folders and print one row per instance.
    Bench(BenchArgs),
    /// The hatch experiment of the APMCM hatch paper (docs/REFERENCES.md): counts, lengths and
    /// times of zigzag and contour fills.
    HatchBench(hatch_bench::HatchBenchArgs),
    /// Order plain point sets (TSPLIB or SVG) with the ordering engine, for comparison with
    /// LKH or Concorde; or write the random point sets the benchmarks use.
    Tsp(tsp::TspArgs),
    /// Write a LinuxCNC machine configuration (INI, HAL, a headless runner) for a profile.
    LinuxcncConfig(linuxcnc::LinuxcncConfigArgs),
    /// Seed 002's experiment: a scan-field layout laid on a spherical cap, its placements
    /// ordered as is, by 3-D distance and by 5-axis time, each timed on a 5-axis profile.
    CapBench(cap::CapBenchArgs),
}

/// Field placement, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum FieldsArg {
    /// Set cover: fewest fields, least overlap, centred.
    Auto,
    /// The scan-field paper's placement (docs/REFERENCES.md): random fields, removal test, unit
    /// moves (slow).
    Paper,
    /// Greedy serpentine cover (baseline).
    Greedy,
}

/// Ordering algorithm, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum AlgoArg {
    /// Heuristic ordering (HHA: fields, then geometries in each) with exact start vertices and
    /// local search.
    Hha,
    /// Genetic algorithm (HGA) on the job's objective, seeded with the HHA plan.
    Hga,
    /// Fields in creation order, nearest neighbour inside each.
    Baseline,
    /// Fields and geometries in document order, no optimisation (a reference to compare with).
    AsIs,
}

/// How the machine moves, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum MotionArg {
    /// The faster of step-and-scan and on the fly on the lowered job time (geometries larger than
    /// a field: marked whole on the fly or cut at field borders, whichever is faster).
    Auto,
    /// Step-and-scan: the stage stops at every field.
    Step,
    /// On the fly: the stage moves on a continuous route while the scanner marks.
    OnTheFly,
}

/// The stage route on the fly, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum StageRouteArg {
    /// galvoplan's own: per axis the stage tracks the laser point within the scanner's reach at
    /// the axis limits (the taut string, blended, where tracking does not settle).
    Taut,
    /// Line-simplified route: the polyline through the simplified pattern points.
    Lsa,
    /// Genetic-algorithm route: a close-enough TSP through circles around the simplified points.
    CetspGa,
}

/// What the ordering minimises, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum CostArg {
    /// Machine time of the lowered toolpath (stage trapezoids and settling, scanner jumps).
    Time,
    /// Idle travel in mm (laser-off distance, the machine's dynamics ignored).
    Distance,
}

/// Start-vertex choice, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum VertexArg {
    /// VEA, then the exact layered-graph shortest path.
    Exact,
    /// The vertex estimate alone (each start vertex nearest the next geometry, improved in
    /// passes).
    Vea,
}

/// Options shared by `plan` and `bench`.
#[derive(Args, Debug, Clone)]
struct JobOpts {
    /// Machine profile: a TOML file or a built-in name (seed000, small-field, linuxcnc,
    /// five-axis, rotary); default seed000, or a project's own profile when the input is a
    /// project.
    #[arg(long)]
    profile: Option<String>,
    /// Scan-field placement.
    #[arg(long, value_enum, default_value = "auto")]
    fields: FieldsArg,
    /// Ordering algorithm.
    #[arg(long, value_enum, default_value = "hha")]
    algo: AlgoArg,
    /// What the ordering minimises: job time or idle distance.
    #[arg(long, value_enum, default_value = "time")]
    cost: CostArg,
    /// Step-and-scan, on the fly (the stage moves while the scanner marks), or whichever runs
    /// the job faster.
    #[arg(long, value_enum, default_value = "auto")]
    motion: MotionArg,
    /// The stage route on the fly.
    #[arg(long, value_enum, default_value = "taut")]
    stage_route: StageRouteArg,
    /// cetsp-ga: population size (the route paper's: 50).
    #[arg(long, default_value_t = 50)]
    route_population: usize,
    /// cetsp-ga: generations (the route paper's: 500).
    #[arg(long, default_value_t = 500)]
    route_generations: usize,
    /// cetsp-ga: crossover rate p_c (the route paper's: 1.0).
    #[arg(long, default_value_t = 1.0)]
    route_crossover: f64,
    /// cetsp-ga: mutation rate p_m (the route paper's: 0.5).
    #[arg(long, default_value_t = 0.5)]
    route_mutation: f64,
    /// lsa and cetsp-ga: padding radius in mm (default: half the field, its inscribed circle).
    #[arg(long)]
    padding_radius_mm: Option<f64>,
    /// Start vertices: exact (layered-graph DP after the estimate) or vea (the estimate only).
    #[arg(long, value_enum, default_value = "exact")]
    vertex: VertexArg,
    /// Directional penalty weight w of the heuristic's field ordering (0.1 is used with one
    /// field).
    #[arg(long, default_value_t = 0.5)]
    direction_weight: f64,
    /// HGA: do not put the HHA plan into the initial population (the paper's HGA; it may then
    /// end worse than HHA).
    #[arg(long)]
    no_hha_seed: bool,
    /// HGA: without a time limit, stop after this many generations without improvement.
    #[arg(long, value_name = "N", default_value_t = galvoplan::document::GaParams::default().stall_generations)]
    ga_stall: usize,
    /// HGA: stop after this many generations at most (default: no cap).
    #[arg(long, value_name = "N")]
    ga_generations: Option<usize>,
    /// HGA: initial population size (between its min 16 and max 48).
    #[arg(long, value_name = "N", default_value_t = galvoplan::document::GaParams::default().population)]
    ga_population: usize,
    /// Run HHA as the scan-field paper describes it (no local search, no alternation), for
    /// comparison.
    #[arg(long)]
    seed_hha: bool,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Time limit for the ordering stage, s.
    #[arg(long)]
    time_limit: Option<f64>,
    /// Cut geometries larger than a scan field at field borders (else they are an error).
    #[arg(long)]
    split_oversize: bool,
    /// A cylinder job: the artwork is the unrolled surface (x along the axis, y around it in mm
    /// of arc) of a cylinder of this diameter, mm, marked strip by strip on the rotary A axis
    /// (the profile needs an A axis and [scanner] depth_of_focus_mm).
    #[arg(long, value_name = "DIAMETER_MM")]
    cylinder: Option<f64>,
    /// Chord tolerance for flattening curves, mm.
    #[arg(long, default_value_t = 0.01)]
    chord_tol: f64,
    /// Where the artwork goes on the machine: auto (as in the file where the laser reaches all
    /// of it, else centred on the base stroke with a warning), as-is, centre (centred on the
    /// base stroke), or corner:X,Y (its top-left corner at X,Y mm; y down).
    #[arg(long, default_value = "auto", value_name = "auto|as-is|centre|corner:X,Y", value_parser = parse_place)]
    place: Place,
    /// Import what the drawing hides on layers: DXF layers that are off or frozen, SVG layers
    /// (top-level groups) with display:none. Invisible DXF entities and hidden SVG shapes stay
    /// out.
    #[arg(long)]
    include_hidden_layers: bool,
    /// Hatch the closed shapes: STYLE:SPACING_MM[:ANGLE_DEG], STYLE = zigzag | lines | cross |
    /// contour (a layer's closed shapes form one region, even-odd; see --hatch-shapes).
    #[arg(long, value_name = "STYLE:SPACING_MM[:ANGLE_DEG]")]
    hatch: Option<String>,
    /// Pens by layer (TOML: `version = 1`, `[default]`, `[[layer]]` with `name`, `enabled`,
    /// `mark_speed_mm_s`, `power`, `frequency_khz`, `passes`, `shift_passes`, `seam`, `colour`,
    /// `[layer.hatch]`); layers it does not name get its default pen, with --hatch as that pen's
    /// hatch.
    #[arg(long, value_name = "PENS.toml")]
    pens: Option<PathBuf>,
    /// Hatch edge offset from the outline, mm (default: one spacing).
    #[arg(
        long,
        value_name = "MM",
        requires = "hatch",
        allow_negative_numbers = true
    )]
    hatch_edge: Option<f64>,
    /// Outlines of hatched shapes: marked before the hatch, after it, or not at all.
    #[arg(long, value_enum, requires = "hatch")]
    hatch_outline: Option<OutlineArg>,
    /// Which closed shapes of a layer are filled as one region: together (even-odd across the
    /// layer: a shape inside another is a hole) or apart (each drawing element on its own).
    #[arg(long, value_enum, requires = "hatch")]
    hatch_shapes: Option<ShapesArg>,
    /// How strokes are cut where they cross a seam (artwork larger than a field): straight,
    /// overlap:D[:doubled] (each side marks D mm past the cut; kept dose alternates the ends
    /// line by line, doubled marks 2·D twice), interlocked:BAND (cuts alternate ±BAND/2 line by
    /// line) or staggered:BAND[:SEED] (a seeded random offset per line within the band). The
    /// default pen's; a pen library sets it per layer (`seam = "..."`).
    #[arg(long, value_name = "FORM", default_value = "straight", value_parser = parse_seam)]
    seam: SeamForm,
    #[command(flatten)]
    tray: TrayOpts,
}

/// A production job: the artwork is a part repeated over a tray, its texts' fields
/// (`{serial:05}`, `{date}`, `{csv:lot}`, …) filled in per part.
#[derive(Args, Debug, Clone, Default)]
struct TrayOpts {
    /// Repeat the artwork COLSxROWS times, PITCH_X and PITCH_Y mm apart (e.g. 6x8@40,32),
    /// from where it is placed; the whole tray is one job.
    #[arg(long, value_name = "COLSxROWS@PITCH_X,PITCH_Y", value_parser = parse_tray)]
    array: Option<Tray>,
    /// Cells left out (broken fixture positions): cell numbers row by row from 1 (e.g. 3,17);
    /// they take no serial and no data row.
    #[arg(long, value_name = "CELLS", requires = "array", value_parser = parse_skip_arg)]
    skip: Option<Cells>,
    /// How the marked parts are numbered: row by row from the top-left, or serpentine.
    #[arg(long, value_name = "rows|serpentine", requires = "array", value_parser = parse_numbering)]
    numbering: Option<Numbering>,
    /// Serial numbers: part k gets START + STEP·(k − 1) (STEP 1 unless given).
    #[arg(long, value_name = "START[:STEP]", value_parser = parse_serial)]
    serial: Option<Serial>,
    /// Data per part: a CSV file with a header row, then row k for part k (`{csv:COLUMN}`).
    #[arg(long, value_name = "FILE.csv")]
    data: Option<PathBuf>,
    /// The date and time `{date}` and `{time}` show (default: now), for reproducible programs.
    #[arg(long, value_name = "YYYY-MM-DD[THH:MM]", value_parser = parse_date)]
    date: Option<Stamp>,
    /// A code on every part: KIND (datamatrix, qr, code128), CONTENT (fields allowed; the last
    /// `@` ends it), its top-left X,Y from the part's top-left and its width SIZE_MM without the
    /// quiet zone; OPTIONS: inverted, rect, gs1 (DataMatrix), ecc=L|M|Q|H (QR). Repeatable.
    #[arg(long = "code", value_name = "KIND:CONTENT@X,Y:SIZE_MM[:OPTIONS]", value_parser = parse_code)]
    codes: Vec<CodeSpec>,
}

impl TrayOpts {
    /// The options as the library takes them (the data file read here).
    fn settings(&self) -> Result<TraySettings> {
        Ok(TraySettings {
            tray: self.array.clone(),
            skip: self.skip.as_ref().map(|c| c.0.clone()),
            numbering: self.numbering,
            serial: self.serial,
            stamp: self.date,
            data: self.data.as_deref().map(DataTable::read).transpose()?,
            codes: (!self.codes.is_empty()).then(|| self.codes.clone()),
        })
    }
}

fn parse_tray(s: &str) -> Result<Tray, String> {
    Tray::parse(s).map_err(|e| e.to_string())
}

/// Tray cells as `--skip` lists them.
#[derive(Debug, Clone)]
struct Cells(Vec<u32>);

fn parse_skip_arg(s: &str) -> Result<Cells, String> {
    galvoplan::document::production::parse_skip(s)
        .map(Cells)
        .map_err(|e| e.to_string())
}

fn parse_numbering(s: &str) -> Result<Numbering, String> {
    s.parse()
        .map_err(|e: galvoplan::document::ProductionError| e.to_string())
}

fn parse_serial(s: &str) -> Result<Serial, String> {
    Serial::parse(s).map_err(|e| e.to_string())
}

fn parse_code(s: &str) -> Result<CodeSpec, String> {
    CodeSpec::parse(s).map_err(|e| e.to_string())
}

fn parse_date(s: &str) -> Result<Stamp, String> {
    Stamp::parse(s).map_err(|e| e.to_string())
}

/// Parses `--seam`.
fn parse_seam(s: &str) -> Result<SeamForm, String> {
    SeamForm::parse(s).map_err(|e| e.to_string())
}

/// Which shapes are filled together, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum ShapesArg {
    /// All closed shapes of a layer form one region (even-odd).
    Together,
    /// Each drawing element is filled on its own.
    Apart,
}

/// Outline handling of hatched shapes, as on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum OutlineArg {
    /// Outline first, then the hatch.
    Before,
    /// Hatch first, then the outline.
    After,
    /// Hatch only.
    None,
}

impl PlanArgs {
    /// The files the job reads: no output may be one of them.
    fn inputs(&self) -> Vec<&std::path::Path> {
        let mut v = vec![self.input.as_path()];
        v.extend(self.job.pens.as_deref());
        v.extend(self.job.tray.data.as_deref());
        if let Some(profile) = self.job.profile.as_deref().map(std::path::Path::new) {
            if profile.exists() {
                v.push(profile);
            }
        }
        v
    }
    /// The files the job writes, with what each is.
    fn outputs(&self) -> Vec<(&'static str, &std::path::Path)> {
        let mut v = vec![("G-code", self.output.as_path())];
        let optional = [
            ("report", &self.report),
            ("preview", &self.preview),
            ("rerun recording", &self.rerun),
            ("geometry SVG", &self.export_geometry),
            ("trajectory", &self.trajectory),
            ("waypoints", &self.waypoints),
            ("parts log", &self.parts_log),
            ("stream", &self.stream),
        ];
        v.extend(
            optional
                .iter()
                .filter_map(|(w, p)| Some((*w, p.as_deref()?))),
        );
        v
    }
}

impl JobOpts {
    /// The profile given, else the built-in `seed000`.
    fn profile(&self) -> Result<MachineProfile> {
        Ok(MachineProfile::load(
            self.profile.as_deref().unwrap_or("seed000"),
        )?)
    }
    /// The profile given, else `input`'s own when it is a project, else `seed000`.
    fn profile_for(&self, input: &std::path::Path) -> Result<MachineProfile> {
        if self.profile.is_none() && input.extension().is_some_and(|e| e == "galvoplan") {
            return Ok(galvoplan::document::load_project(input)?.profile);
        }
        self.profile()
    }
    fn settings(&self) -> Result<SolverSettings> {
        let s = self.unchecked_settings()?;
        s.validate().map_err(|e| {
            let flag = match e.key.as_str() {
                "direction_weight" => " (--direction-weight)",
                "time_limit_s" => " (--time-limit)",
                "ga.stall_generations" => " (--ga-stall)",
                "ga.max_generations" => " (--ga-generations)",
                "ga.population" => " (--ga-population)",
                "cylinder.diameter_mm" => " (--cylinder)",
                _ => "",
            };
            anyhow::anyhow!("invalid settings: {e}{flag}")
        })?;
        Ok(s)
    }
    fn pens(&self) -> Result<Option<PenLibrary>> {
        self.pens
            .as_deref()
            .map(PenLibrary::load)
            .transpose()
            .map_err(Into::into)
    }
    fn unchecked_settings(&self) -> Result<SolverSettings> {
        Ok(SolverSettings {
            fields: match self.fields {
                FieldsArg::Auto => FieldsMode::Auto,
                FieldsArg::Paper => FieldsMode::Paper,
                FieldsArg::Greedy => FieldsMode::Greedy,
            },
            algo: match self.algo {
                AlgoArg::Hha => Algo::Hha,
                AlgoArg::Hga => Algo::Hga,
                AlgoArg::Baseline => Algo::Baseline,
                AlgoArg::AsIs => Algo::AsIs,
            },
            motion: match self.motion {
                MotionArg::Auto => MotionMode::Auto,
                MotionArg::Step => MotionMode::Step,
                MotionArg::OnTheFly => MotionMode::OnTheFly,
            },
            stage_route: match self.stage_route {
                StageRouteArg::Taut => StageRouteKind::Taut,
                StageRouteArg::Lsa => StageRouteKind::Lsa,
                StageRouteArg::CetspGa => StageRouteKind::CetspGa,
            },
            route_ga: RouteGaSettings {
                population: self.route_population,
                generations: self.route_generations,
                crossover_rate: self.route_crossover,
                mutation_rate: self.route_mutation,
                padding_radius_mm: self.padding_radius_mm,
            },
            cost_model: match self.cost {
                CostArg::Time => CostModel::Time,
                CostArg::Distance => CostModel::Distance,
            },
            seed: self.seed,
            time_limit_s: self.time_limit,
            split_oversize: self.split_oversize,
            vertex: match self.vertex {
                VertexArg::Exact => VertexMode::Exact,
                VertexArg::Vea => VertexMode::Vea,
            },
            hha_improve: !self.seed_hha,
            direction_weight: self.direction_weight,
            ga: galvoplan::document::GaParams {
                seed_with_hha: !self.no_hha_seed,
                stall_generations: self.ga_stall,
                max_generations: self.ga_generations,
                population: self.ga_population,
                ..Default::default()
            },
            hatch: self.hatch()?,
            seam: self.seam,
            cylinder: self
                .cylinder
                .map(|diameter_mm| galvoplan::document::Cylinder { diameter_mm }),
        })
    }
    fn hatch(&self) -> Result<Option<HatchSettings>> {
        let Some(spec) = &self.hatch else {
            return Ok(None);
        };
        let mut h = HatchSettings::parse_spec(spec).map_err(|e| anyhow::anyhow!("--hatch {e}"))?;
        h.edge_offset_mm = self.hatch_edge;
        if let Some(o) = self.hatch_outline {
            h.outline = match o {
                OutlineArg::Before => OutlineMode::Before,
                OutlineArg::After => OutlineMode::After,
                OutlineArg::None => OutlineMode::None,
            };
        }
        if let Some(shapes) = self.hatch_shapes {
            h.shapes = match shapes {
                ShapesArg::Together => FillShapes::Together,
                ShapesArg::Apart => FillShapes::Apart,
            };
        }
        h.check().map_err(|e| anyhow::anyhow!("--hatch: {e}"))?;
        Ok(Some(h))
    }
    fn import(&self) -> Result<ImportOptions> {
        anyhow::ensure!(
            self.chord_tol.is_finite() && self.chord_tol > 0.0,
            "--chord-tol must be a positive number of mm, got {}",
            self.chord_tol
        );
        Ok(ImportOptions {
            chord_tol_mm: self.chord_tol,
            place: self.place,
            hidden_layers: if self.include_hidden_layers {
                HiddenLayers::IncludeAll
            } else {
                HiddenLayers::Skip
            },
            ..ImportOptions::default()
        })
    }
}

fn parse_place(s: &str) -> Result<Place, String> {
    s.parse()
        .map_err(|e: galvoplan::import::PlaceError| e.to_string())
}

#[derive(Args, Debug)]
struct PlanArgs {
    /// Input SVG or DXF.
    input: PathBuf,
    /// Output G-code.
    #[arg(short, long)]
    output: PathBuf,
    /// JSON report.
    #[arg(long)]
    report: Option<PathBuf>,
    /// SVG preview of the planned path.
    #[arg(long)]
    preview: Option<PathBuf>,
    /// Record the run (geometry, fields, path, GA convergence) as a rerun .rrd file
    /// (`--rerun` is the same option; builds without the `rerun` feature refuse it).
    #[arg(long = "record", visible_alias = "rerun", value_name = "OUT.rrd")]
    rerun: Option<PathBuf>,
    /// Write exactly the geometry to be marked as an SVG in mm.
    #[arg(long)]
    export_geometry: Option<PathBuf>,
    /// Write the sampled stage + scanner trajectory as CSV
    /// (`t_s,stage_x_mm,stage_y_mm,scan_x_mm,scan_y_mm,laser`).
    #[arg(long, value_name = "OUT.csv")]
    trajectory: Option<PathBuf>,
    /// Sampling period of the trajectory, ms: the profile's controller clock when it has one
    /// (another period is refused), else 1 ms. The trajectory samples the plan; it never
    /// changes it.
    #[arg(long, value_name = "MS", requires = "trajectory")]
    trajectory_period_ms: Option<f64>,
    /// Write the stream of a streamed on-the-fly plan (a LinuxCNC profile with
    /// `[controller] stream_period_s`): one line per stream period, `X Y U V laser end`, which
    /// the machine's `streamer` feeds to the joints while the program waits (docs/GCODE.md).
    #[arg(long, value_name = "JOB.stream")]
    stream: Option<PathBuf>,
    /// Write the toolpath's exact states at every segment end and mark vertex (on the fly: and
    /// every millisecond of planned time, the on-the-fly program's samples) as CSV, in the
    /// trajectory's columns: what a controller's canonical moves are checked against.
    #[arg(long, value_name = "OUT.csv")]
    waypoints: Option<PathBuf>,
    /// Append one row per part marked (date-time, program, part, serial, texts) to this CSV
    /// file, once the program is written.
    #[arg(long, value_name = "FILE.csv")]
    parts_log: Option<PathBuf>,
    #[command(flatten)]
    job: JobOpts,
}

#[derive(Args, Debug)]
struct BenchArgs {
    /// SVG files or folders of SVGs.
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Also write the rows as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Runs per instance and seed; times are medians.
    #[arg(long, default_value_t = 1)]
    repeat: usize,
    /// Seeds per instance (from --seed on); quality is reported as mean ± sd.
    #[arg(long, default_value_t = 1)]
    seeds: usize,
    #[command(flatten)]
    job: JobOpts,
}

/// Entry point: parses arguments, runs, prints a one-line error on failure.
pub fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Plan(a)) => plan::run(&a),
        Some(Command::Bench(a)) => bench::run(&a),
        Some(Command::HatchBench(a)) => hatch_bench::run(&a),
        Some(Command::Tsp(a)) => tsp::run(&a),
        Some(Command::LinuxcncConfig(a)) => linuxcnc::run(&a),
        Some(Command::CapBench(a)) => cap::run(&a),
        None => open_gui(cli.file),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let msg = one_line(&e);
            eprintln!("galvoplan: error: {msg}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// `n` and the noun for it: "1 geometry", "3 geometries".
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// What the operator can do about an error, in the command line's words.
fn hint(e: &anyhow::Error) -> Option<&'static str> {
    use galvoplan::pipeline::{PipelineError, Remedy};
    let remedy = e
        .chain()
        .find_map(|c| c.downcast_ref::<PipelineError>())?
        .remedy()?;
    Some(match remedy {
        Remedy::SplitOversize => {
            "use --split-oversize to cut them at field borders, or --motion auto or on-the-fly"
        }
        Remedy::Place => "use --place centre or --place corner:X,Y",
        Remedy::Cylinder => {
            "the machine turns the part on its A axis instead of moving it in Y: use --cylinder \
             DIAMETER_MM to mark around it"
        }
    })
}

/// The error and its causes on one line, skipping causes already quoted by their parent, then
/// what could help.
fn one_line(e: &anyhow::Error) -> String {
    let hint = hint(e).map_or(String::new(), |h| format!(" ({h})"));
    one_line_causes(e) + &hint
}

/// The error and its causes on one line.
fn one_line_causes(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !msg.contains(&text) {
            if !msg.is_empty() {
                msg.push_str(": ");
            }
            msg.push_str(&text);
        }
    }
    msg.replace('\n', " ")
}

#[cfg(feature = "gui")]
fn open_gui(file: Option<PathBuf>) -> Result<()> {
    galvoplan::app::run(file)
}

#[cfg(not(feature = "gui"))]
fn open_gui(_file: Option<PathBuf>) -> Result<()> {
    anyhow::bail!(
        "this build has no GUI (built without the `gui` feature); use a subcommand, see --help"
    )
}
