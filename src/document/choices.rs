//! The choices the editors offer, in an operator's words: each option's value, its label and
//! what it does (with the command line's name for it). The GUI's combo boxes and the spec
//! table's text form of a choice ([`super::spec`]) both read these tables, so an option is
//! worded once.

use super::{
    CodeKind, ControllerKind, CostModel, FieldsMode, GcodeMode, MotionMode, Numbering,
    StageRouteKind, VertexMode,
};

/// One option of a choice: its value, its words, and what it does (with the command line's
/// name for it).
pub type Choice<T> = (T, &'static str, &'static str);

/// The G-code dialects offered, in words.
pub const GCODE_DIALECTS: &[Choice<GcodeMode>] = &[
    (
        GcodeMode::Tcp,
        "Tool-centre point (X/Y)",
        "The laser point's path on X/Y; the controller splits it between stage and scanner.",
    ),
    (
        GcodeMode::StageScanner,
        "Stage and scanner axes",
        "G0 X/Y to each scan field, the scanner on its own two axis words (step-and-scan).",
    ),
    (
        GcodeMode::Linuxcnc,
        "LinuxCNC (X/Y stage, U/V scanner)",
        "One LinuxCNC machine: the laser on a digital output (M62/M63), exact stops in \
         step-and-scan, timed G93 lines on the fly; `galvoplan linuxcnc-config` writes the \
         machine's configuration.",
    ),
];

/// The controllers offered, in words.
pub const CONTROLLERS: &[Choice<ControllerKind>] = &[
    (
        ControllerKind::Ideal,
        "Scan-head controller",
        "Job time as a scan head runs it: marks at constant speed through corners, jumps at \
         jump speed, delays as given.",
    ),
    (
        ControllerKind::Linuxcnc,
        "LinuxCNC",
        "Job time as LinuxCNC's planner runs the program: every move to rest in whole servo \
         periods; on the fly its blends, slower than planned.",
    ),
];

/// The field placements offered, in words.
pub const FIELD_PLACEMENTS: &[Choice<FieldsMode>] = &[
    (
        FieldsMode::Auto,
        "Fewest fields (automatic)",
        "As few scan fields as the search finds (a set cover); command line: --fields auto.",
    ),
    (
        FieldsMode::Paper,
        "Reference paper's method",
        "The scan-field paper's placement (random fields, removal test, unit moves), for comparison; command line: \
         --fields paper.",
    ),
    (
        FieldsMode::Greedy,
        "Quick greedy cover",
        "Fields added one at a time where they cover the most (the baseline); command line: \
         --fields greedy.",
    ),
];

/// The start-point choices offered, in words.
pub const START_POINTS: &[Choice<VertexMode>] = &[
    (
        VertexMode::Exact,
        "Best start points (exact)",
        "Where each closed shape starts and which way each open one runs, chosen exactly for \
         the order found (VEA, then an exact search); command line: --vertex exact.",
    ),
    (
        VertexMode::Vea,
        "Quick start points (estimate)",
        "The estimate alone (each start vertex nearest the next geometry), for comparison; command line: --vertex vea.",
    ),
];

/// The cost models offered, in words.
pub const COST_MODELS: &[Choice<CostModel>] = &[
    (
        CostModel::Time,
        "Job time (machine dynamics)",
        "The machine's time for the job; command line: --cost time.",
    ),
    (
        CostModel::Distance,
        "Idle travel distance",
        "The laser-off travel in mm, ignoring the machine's dynamics; \
         command line: --cost distance.",
    ),
];

/// The motion modes offered, in words.
pub const MOTION_MODES: &[Choice<MotionMode>] = &[
    (
        MotionMode::Auto,
        "Automatic (the faster)",
        "Plans step-and-scan and on the fly and keeps the faster job; command line: --motion auto.",
    ),
    (
        MotionMode::Step,
        "Step-and-scan",
        "The stage stops at each scan field; command line: --motion step.",
    ),
    (
        MotionMode::OnTheFly,
        "On the fly (stage moves while marking)",
        "The stage never stops; command line: --motion on-the-fly.",
    ),
];

/// The stage routes offered, in words.
pub const STAGE_ROUTES: &[Choice<StageRouteKind>] = &[
    (
        StageRouteKind::Taut,
        "Tracked route (default)",
        "The stage follows the laser point as closely as its speed and acceleration allow, \
         and the marking waits only where it cannot keep up; command line: --stage-route taut.",
    ),
    (
        StageRouteKind::Lsa,
        "Follow a simplified path of the marks",
        "The stage follows the marks' points, thinned out by line simplification (a \
         published benchmark route); command line: --stage-route lsa.",
    ),
    (
        StageRouteKind::CetspGa,
        "Genetic algorithm route (slow)",
        "A route through circles around the marks, searched by a genetic algorithm (a \
         published benchmark route); command line: --stage-route cetsp-ga.",
    ),
];

/// The kinds of code offered, in words.
pub const CODE_KINDS: &[Choice<CodeKind>] = &[
    (
        CodeKind::DataMatrix,
        "DataMatrix",
        "DataMatrix ECC200; options rect, gs1, dots, inverted",
    ),
    (
        CodeKind::Qr,
        "QR code",
        "QR code; options ecc=L|M|Q|H, dots, inverted",
    ),
    (
        CodeKind::Code128,
        "Code 128",
        "a 1-D Code 128 (printable ASCII); option inverted",
    ),
];

/// The ways of numbering a tray's parts, in words.
pub const NUMBERINGS: &[Choice<Numbering>] = &[
    (
        Numbering::Rows,
        "Row by row",
        "parts numbered along each row from the top-left, every row left to right",
    ),
    (
        Numbering::Serpentine,
        "Serpentine",
        "parts numbered along each row from the top-left, every other row right to left",
    ),
];

/// The label of `value` in `options` (`?` when it has none: a test keeps every table whole).
pub fn label_of<T: PartialEq>(options: &[Choice<T>], value: &T) -> &'static str {
    options
        .iter()
        .find(|(v, ..)| v == value)
        .map_or("?", |o| o.1)
}
