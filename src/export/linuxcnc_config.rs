//! A LinuxCNC machine configuration from a machine profile (docs/GCODE.md, *LinuxCNC*):
//! `galvoplan linuxcnc-config --profile P.toml --out DIR`.
//!
//! One trivkins machine with a joint per axis: X and Y for the stage, the profile's axes beyond
//! X/Y (Z in mm, rotaries A and B in degrees, `TYPE = ANGULAR`), and the profile's two scanner
//! axis words (default U, V) for the scanner, with the profile's stroke, travels, field, speeds
//! and accelerations as limits, and a digital output for the laser. A flat profile's machine is
//! XYUV with four joints; seed 002's 5-axis machine is XYZABUV with seven. The files:
//!
//! * `galvoplan.ini`: the machine, with `[EMCMOT] SERVO_PERIOD` from the profile's controller;
//! * `galvoplan.hal`: motion, and the simulated machine (each joint's command looped back as its
//!   feedback, the E-stop and tool-change loopbacks);
//! * `galvoplan-timers.hal`: servo-period timers of the running program, the laser output, the
//!   moving laser and the job (from the laser's first switch-on), read by the runner;
//! * `galvoplan-run.py`: a display that runs one program without a screen and writes a JSON
//!   result (used by `scripts/check-linuxcnc.sh`);
//! * `README.txt`: how to run it, and which pins a real machine's Mesa card takes instead of the
//!   loopbacks.

use crate::document::{ExtraAxisId, GcodeMode, MachineProfile};
use std::fmt::Write;

/// Headroom added to every axis limit, mm: positions written with the dialect's decimals may
/// round past a limit by half a unit of the last place.
pub const LIMIT_MARGIN_MM: f64 = 0.001;

/// The digital input that tells a streamed job's program the stream reached its last sample
/// (`M66 P0`; the stream's `end` column, [`super::stream_text`]).
pub const STREAM_END_INPUT: u32 = 0;

/// The digital output that hands the joints and the laser to the stream (`M64`/`M65`): the one
/// after the laser's.
pub fn stream_output(profile: &MachineProfile) -> u32 {
    profile.gcode.laser_output + 1
}

/// One file of a configuration: its name in the output folder and its text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigFile {
    /// File name (no folders).
    pub name: &'static str,
    /// Contents.
    pub text: String,
    /// Written executable (the runner).
    pub executable: bool,
}

/// The runner LinuxCNC starts as its display (`[DISPLAY] DISPLAY`).
const RUNNER: &str = include_str!("../../assets/linuxcnc/galvoplan-run.py");

/// The limits of an axis without a travel (an endless rotary, a Z without `travel_mm`), mm or
/// deg: far beyond any position a program reaches, well within LinuxCNC's own default (±1e99).
pub const ENDLESS_LIMIT: f64 = 1e9;

/// What an axis of the configuration moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// The X/Y stage.
    Stage,
    /// Z, A or B.
    Extra(ExtraAxisId),
    /// The scanner.
    Scanner,
}

/// One axis of the configuration (and its joint, the same index). Units are mm, or degrees for
/// a rotary (the `_mm` fields then hold degrees).
struct Axis {
    letter: String,
    role: Role,
    min_mm: f64,
    max_mm: f64,
    velocity_mm_s: f64,
    accel_mm_s2: f64,
    /// Where homing in place puts it: 0, or the travel's nearer end when 0 is outside it.
    home: f64,
}

impl Axis {
    fn angular(&self) -> bool {
        matches!(self.role, Role::Extra(ExtraAxisId::A | ExtraAxisId::B))
    }
}

/// The joint of the axis named `letter`, if the machine has it.
fn joint_of(axes: &[Axis], letter: &str) -> Option<usize> {
    axes.iter().position(|a| a.letter == letter)
}

/// The joints of the scanner's two axes.
fn scanner_joints(axes: &[Axis]) -> [usize; 2] {
    let n = axes.len();
    [n - 2, n - 1]
}

/// The configuration files for `profile` (see the module documentation).
pub fn linuxcnc_config(profile: &MachineProfile) -> Vec<ConfigFile> {
    let axes = axes(profile);
    let stream = profile.controller.stream_period_s.map(|_| ConfigFile {
        name: "galvoplan-stream.hal",
        text: stream_hal(profile, &axes),
        executable: false,
    });
    let mut files = vec![
        ConfigFile {
            name: "galvoplan.ini",
            text: ini(profile, &axes),
            executable: false,
        },
        ConfigFile {
            name: "galvoplan.hal",
            text: hal(profile, &axes),
            executable: false,
        },
        ConfigFile {
            name: "galvoplan-timers.hal",
            text: timers_hal(profile),
            executable: false,
        },
        ConfigFile {
            name: "galvoplan-run.py",
            text: RUNNER.to_string(),
            executable: true,
        },
        ConfigFile {
            name: "galvoplan.tbl",
            text: "T1 P1 D0 Z0 ;no tools: a laser\n".into(),
            executable: false,
        },
        ConfigFile {
            name: "README.txt",
            text: readme(profile, &axes),
            executable: false,
        },
    ];
    files.extend(stream);
    files
}

fn axes(profile: &MachineProfile) -> Vec<Axis> {
    let half = |k: usize| profile.field_mm[k] / 2.0 + LIMIT_MARGIN_MM;
    let scanner_velocity = profile
        .scanner
        .jump_speed_mm_s
        .max(profile.scanner.mark_speed_mm_s);
    let words = &profile.gcode.scanner_axes;
    let stage = |letter: &str, k: usize, limits: &crate::document::AxisLimits| Axis {
        letter: letter.into(),
        role: Role::Stage,
        min_mm: -LIMIT_MARGIN_MM,
        max_mm: profile.stroke_mm[k] + LIMIT_MARGIN_MM,
        velocity_mm_s: limits.max_velocity_mm_s,
        accel_mm_s2: limits.max_accel_mm_s2,
        home: 0.0,
    };
    let scanner = |k: usize| Axis {
        letter: words[k].trim().to_uppercase(),
        role: Role::Scanner,
        min_mm: -half(k),
        max_mm: half(k),
        velocity_mm_s: scanner_velocity,
        accel_mm_s2: profile.controller.scanner_accel_mm_s2,
        home: 0.0,
    };
    let extra = |id: ExtraAxisId| {
        let a = profile.extra_axis(id)?;
        let ([min, max], margin) = match a.travel {
            Some(t) => (t, LIMIT_MARGIN_MM),
            None => ([-ENDLESS_LIMIT, ENDLESS_LIMIT], 0.0),
        };
        Some(Axis {
            letter: id.word().into(),
            role: Role::Extra(id),
            min_mm: min - margin,
            max_mm: max + margin,
            velocity_mm_s: a.max_velocity,
            accel_mm_s2: a.max_accel,
            home: 0.0_f64.clamp(min, max),
        })
    };
    let mut axes = vec![stage("X", 0, &profile.axis_x)];
    if profile.has_y() {
        axes.push(stage("Y", 1, &profile.axis_y));
    }
    axes.extend(ExtraAxisId::ALL.into_iter().filter_map(extra));
    axes.push(scanner(0));
    axes.push(scanner(1));
    axes
}

fn num(v: f64) -> String {
    crate::geom::format_mm(v, 6)
}

fn ini(profile: &MachineProfile, axes: &[Axis]) -> String {
    let coords: String = axes.iter().map(|a| a.letter.as_str()).collect();
    let servo_ns = (profile.controller.servo_period_s * 1e9).round() as u64;
    let fastest = axes
        .iter()
        .filter(|a| !a.angular())
        .map(|a| a.velocity_mm_s)
        .fold(0.0, f64::max);
    // rotaries: the fastest's speed, so that neither limit clips a move the axes allow
    let fastest_deg = axes
        .iter()
        .filter(|a| a.angular())
        .map(|a| a.velocity_mm_s)
        .fold(0.0, f64::max);
    let angular = if fastest_deg > 0.0 {
        format!(
            "DEFAULT_ANGULAR_VELOCITY = {v}\nMAX_ANGULAR_VELOCITY = {v}\n",
            v = num(fastest_deg)
        )
    } else {
        String::new()
    };
    let [su, sv] = scanner_joints(axes);
    // the stage's words: X/Y, and the axes beyond them
    let mut stage = String::from(if profile.has_y() { "X/Y" } else { "X" });
    for a in axes.iter().filter(|a| matches!(a.role, Role::Extra(_))) {
        stage.push_str(", ");
        stage.push_str(&a.letter);
    }
    let mut s = String::new();
    let _ = write!(
        s,
        "# LinuxCNC machine for galvoplan profile: {name}
# Written by galvoplan {version} (galvoplan linuxcnc-config). Stage {stage}, scanner {u}/{v}.

[EMC]
VERSION = 1.1
MACHINE = galvoplan {name_short}

[DISPLAY]
# a display that runs one program without a screen (see README.txt); any LinuxCNC GUI
# (axis, gmoccapy) works here too
DISPLAY = ./galvoplan-run.py
CYCLE_TIME = 0.01
POSITION_FEEDBACK = ACTUAL
MAX_FEED_OVERRIDE = 1.0

[TASK]
TASK = milltask
CYCLE_TIME = 0.001

[RS274NGC]
PARAMETER_FILE = galvoplan.var

[EMCMOT]
EMCMOT = motmod
COMM_TIMEOUT = 1.0
SERVO_PERIOD = {servo_ns}
{base}
[EMCIO]
EMCIO = io
CYCLE_TIME = 0.100
TOOL_TABLE = galvoplan.tbl

[HAL]
HALUI = halui
HALFILE = galvoplan.hal
HALFILE = galvoplan-timers.hal
{stream_hal}
[KINS]
KINEMATICS = trivkins coordinates={coords}
JOINTS = {joints}

[TRAJ]
COORDINATES = {coords}
LINEAR_UNITS = mm
ANGULAR_UNITS = degree
DEFAULT_LINEAR_VELOCITY = {default_v}
MAX_LINEAR_VELOCITY = {fastest}
{angular}",
        name = profile.name.replace('\n', " "),
        name_short = profile.name.split(" (").next().unwrap_or("machine"),
        version = env!("CARGO_PKG_VERSION"),
        u = axes[su].letter,
        v = axes[sv].letter,
        joints = axes.len(),
        default_v = num(profile.axis_x.max_velocity_mm_s),
        fastest = num(fastest),
        stream_hal = if profile.controller.stream_period_s.is_some() {
            "HALFILE = galvoplan-stream.hal\n"
        } else {
            ""
        },
        base = profile
            .controller
            .stream_period_s
            .map_or(String::new(), |p| format!(
                "# the thread the stream of a streamed on-the-fly job runs in\nBASE_PERIOD = {}\n",
                (p * 1e9).round() as u64
            )),
    );
    for (j, a) in axes.iter().enumerate() {
        let limits = format!(
            "MIN_LIMIT = {}\nMAX_LIMIT = {}\nMAX_VELOCITY = {}\nMAX_ACCELERATION = {}\n",
            num(a.min_mm),
            num(a.max_mm),
            num(a.velocity_mm_s),
            num(a.accel_mm_s2)
        );
        let _ = write!(
            s,
            "\n[AXIS_{l}]\n{limits}\n[JOINT_{j}]\nTYPE = {kind}\n{limits}FERROR = 1\nMIN_FERROR = 1\n\
             HOME = {home}\nHOME_OFFSET = {home}\nHOME_SEARCH_VEL = 0\nHOME_LATCH_VEL = 0\nHOME_SEQUENCE = 0\n",
            l = a.letter,
            kind = if a.angular() { "ANGULAR" } else { "LINEAR" },
            home = num(a.home),
        );
    }
    s
}

fn hal(profile: &MachineProfile, axes: &[Axis]) -> String {
    let d = &profile.gcode;
    let streams = profile.controller.stream_period_s.is_some();
    let dio = (stream_output(profile) + 1).max(4);
    let aio = d.power_output.map_or(4, |e| (e + 1).max(4));
    let base = if streams {
        "base_period_nsec=[EMCMOT]BASE_PERIOD base_thread_fp=1 "
    } else {
        ""
    };
    let mut s = format!(
        "# Motion and the simulated machine (galvoplan linuxcnc-config).
loadrt [KINS]KINEMATICS
loadrt [EMCMOT]EMCMOT {base}servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS num_dio={dio} num_aio={aio}
addf motion-command-handler servo-thread
addf motion-controller servo-thread

# Simulated machine: each joint's command is its feedback. On a real machine these lines go
# (README.txt): the stage joints to a stepgen or PWM + encoder, the scanner joints to an XY2-100
# module.
"
    );
    for j in 0..axes.len() {
        let _ = writeln!(
            s,
            "net j{j}-pos joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb"
        );
    }
    let _ = write!(
        s,
        "
net tool-prep-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared
net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed
"
    );
    if streams {
        // the joints, the laser and the E-stop loop: galvoplan-stream.hal, loaded after the
        // timers (whose and2/not instances it uses)
        return s;
    }
    let _ = write!(
        s,
        "net estop-loop iocontrol.0.user-enable-out => iocontrol.0.emc-enable-in

# The laser gate: digital output {n} (M62/M63 P{n} in the program).
net laser-gate motion.digital-out-{n:02}
",
        n = d.laser_output
    );
    if let Some(e) = d.power_output {
        let _ = writeln!(
            s,
            "# The laser power: analog output {e} (M67 E{e} Q.. in the program).\nnet laser-power motion.analog-out-{e:02}"
        );
    }
    s
}

/// Samples a stream's FIFO holds: two seconds of the stream, at least 4,096.
fn stream_depth(period_s: f64) -> u64 {
    ((2.0 / period_s).ceil() as u64).max(4096)
}

/// The logic of a streamed job's HAL, loaded with the timers' (a HAL component is loaded once):
/// `and2` and `not` instances.
const STREAM_AND2: &str = ",st-active,st-laser,st-starved,st-starved2,st-enable";
const STREAM_NOT: &str = ",st-full,st-not-end,st-ok";

/// The stream of a streamed on-the-fly job into the joints and the laser (docs/GCODE.md,
/// *Streamed on the fly*): `streamer` in the base thread, `mux2` per joint between motion and
/// the stream, the laser gated by the stream's state in the same period, and an E-stop when the
/// stream runs dry before its last sample. The stream's X, Y, U and V (mux2.0-3) go to those
/// axes' joints; a machine's Z, A and B stay with motion.
fn stream_hal(profile: &MachineProfile, axes: &[Axis]) -> String {
    let d = &profile.gcode;
    let period_s = profile.controller.stream_period_s.unwrap_or(1e-4);
    let depth = stream_depth(period_s);
    let (sel, n) = (stream_output(profile), d.laser_output);
    let power = d.power_output;
    let cfg = if power.is_some() { "ffffbbf" } else { "ffffbb" };
    let muxes = if power.is_some() { 5 } else { 4 };
    let mut s = format!(
        "# Streamed on the fly (docs/GCODE.md): the program hands the joints to the stream with
# M64 P{sel} and waits for its last sample with M66 P{end} L3. The stream's FIFO is fed by
# halstreamer (galvoplan-run.py): one line per base-thread period, X Y U V laser end{pw}.
# While motion.digital-out-{sel:02} is on, each joint follows the stream (mux2), not motion;
# the laser is the stream's bit while the FIFO has samples, so an underrun turns it off in the
# same period, and an underrun before the last sample (end = 0) is an E-stop. The stream
# bypasses LinuxCNC's soft limits: galvoplan and galvoplan-run.py check every sample against
# the axes' limits before it runs. sampler.0 records what the joints and the laser get.
loadrt streamer depth={depth} cfg={cfg}
loadrt sampler depth={depth} cfg=ffffbbbs
loadrt mux2 count={muxes}
loadrt or2 names=st-laser-or
addf streamer.0 base-thread
",
        end = STREAM_END_INPUT,
        pw = if power.is_some() { " power" } else { "" },
    );
    for m in 0..muxes {
        let _ = writeln!(s, "addf mux2.{m} base-thread");
    }
    for f in [
        "st-full",
        "st-not-end",
        "st-active",
        "st-laser",
        "st-laser-or",
        "st-starved",
        "st-starved2",
        "st-ok",
        "sampler.0",
    ] {
        let _ = writeln!(s, "addf {f} base-thread");
    }
    let sels: String = (0..muxes).map(|m| format!(" mux2.{m}.sel")).collect();
    let _ = write!(
        s,
        "addf st-enable servo-thread
net st-select motion.digital-out-{sel:02} => streamer.0.enable{sels} st-active.in0 st-starved2.in1 sampler.0.enable
net st-empty streamer.0.empty => st-full.in st-starved.in0
net st-has st-full.out => st-active.in1
net st-on st-active.out => st-laser.in0
net st-laser-bit streamer.0.pin.4 => st-laser.in1
net st-lit st-laser.out => st-laser-or.in1
net st-end streamer.0.pin.5 => motion.digital-in-{end:02} st-not-end.in sampler.0.pin.5
net st-not-ended st-not-end.out => st-starved.in1
net st-starving st-starved.out => st-starved2.in0
net st-starved-b st-starved2.out => st-ok.in
net st-fine st-ok.out => st-enable.in1
net estop-user iocontrol.0.user-enable-out => st-enable.in0
net estop-loop st-enable.out => iocontrol.0.emc-enable-in
# The laser gate: digital output {n} (M62/M63 P{n}) or the stream's bit.
net g-laser motion.digital-out-{n:02} => st-laser-or.in0
net laser-gate st-laser-or.out => sampler.0.pin.4
net st-empty => sampler.0.pin.6
net st-underruns streamer.0.underruns => sampler.0.pin.7
",
        end = STREAM_END_INPUT,
    );
    let [su, sv] = scanner_joints(axes);
    let joints = [joint_of(axes, "X"), joint_of(axes, "Y"), Some(su), Some(sv)];
    for (m, j) in joints.into_iter().enumerate() {
        if let Some(j) = j {
            let _ = writeln!(s, "net j{j}-pos => mux2.{m}.in0");
        }
        let _ = writeln!(
            s,
            "net st-p{m} streamer.0.pin.{m} => mux2.{m}.in1\nnet m{m}-pos mux2.{m}.out => sampler.0.pin.{m}"
        );
    }
    if let Some(e) = power {
        let _ = writeln!(
            s,
            "# The laser power: analog output {e} (M67 E{e}) or the stream's.\nnet g-power motion.analog-out-{e:02} => mux2.4.in0\nnet st-power streamer.0.pin.6 => mux2.4.in1\nnet laser-power mux2.4.out"
        );
    }
    s
}

/// The timers' HAL file, with a streamed job's logic instances when the profile streams.
fn timers_hal(profile: &MachineProfile) -> String {
    let (and2, not) = if profile.controller.stream_period_s.is_some() {
        (STREAM_AND2, STREAM_NOT)
    } else {
        ("", "")
    };
    TIMERS_HAL
        .replace(
            "loadrt not names=tm-still",
            &format!("loadrt not names=tm-still{not}"),
        )
        .replace(
            "loadrt and2 names=tm-laser-move,tm-job",
            &format!("loadrt and2 names=tm-laser-move,tm-job{and2}"),
        )
}

/// The timers' HAL file (the same for every profile).
const TIMERS_HAL: &str =
    "# Timers of the running program, read by galvoplan-run.py (servo periods added up):
#   t-run: the program runs; t-laser: the laser output is on; t-move: the machine moves;
#   t-laser-move: the laser is on while the machine moves; t-job: from the laser's first
#   switch-on to the program's end (galvoplan's job time starts at the first mark).
loadrt not names=tm-still
loadrt and2 names=tm-laser-move,tm-job
loadrt flipflop names=tm-started
loadrt conv_bit_float names=tm-run-f,tm-laser-f,tm-move-f,tm-laser-move-f,tm-job-f
loadrt integ names=t-run,t-laser,t-move,t-laser-move,t-job
addf tm-still servo-thread
addf tm-laser-move servo-thread
addf tm-started servo-thread
addf tm-job servo-thread
addf tm-run-f servo-thread
addf tm-laser-f servo-thread
addf tm-move-f servo-thread
addf tm-laser-move-f servo-thread
addf tm-job-f servo-thread
addf t-run servo-thread
addf t-laser servo-thread
addf t-move servo-thread
addf t-laser-move servo-thread
addf t-job servo-thread
net laser-gate => tm-laser-f.in tm-laser-move.in0 tm-started.set
net tm-in-position motion.in-position => tm-still.in
net tm-moving tm-still.out => tm-laser-move.in1 tm-move-f.in
net tm-laser-moving tm-laser-move.out => tm-laser-move-f.in
net tm-started-b tm-started.out => tm-job.in0
net tm-job-b tm-job.out => tm-job-f.in
net tm-run-v tm-run-f.out => t-run.in
net tm-laser-v tm-laser-f.out => t-laser.in
net tm-move-v tm-move-f.out => t-move.in
net tm-laser-move-v tm-laser-move-f.out => t-laser-move.in
net tm-job-v tm-job-f.out => t-job.in
# halui's pins exist only once halui runs: galvoplan-run.py nets
# halui.program.is-running to tm-run-f.in and tm-job.in1.
";

fn readme(profile: &MachineProfile, axes: &[Axis]) -> String {
    let d = &profile.gcode;
    let [ju, jv] = scanner_joints(axes);
    let mut axis_lines = String::new();
    for a in &axes[..ju] {
        let (unit, what) = match a.role {
            Role::Extra(ExtraAxisId::A) => ("deg", "rotary about X"),
            Role::Extra(ExtraAxisId::B) => ("deg", "rotary about Y"),
            Role::Extra(ExtraAxisId::Z) => ("mm", "Z"),
            _ => ("mm", "stage"),
        };
        let range = if a.max_mm >= ENDLESS_LIMIT {
            "endless".to_string()
        } else {
            format!("{} .. {} {unit}", num(a.min_mm), num(a.max_mm))
        };
        let _ = writeln!(
            axis_lines,
            "  {l}: {range}, {v} {unit}/s, {acc} {unit}/s^2 ({what})",
            l = a.letter,
            v = num(a.velocity_mm_s),
            acc = num(a.accel_mm_s2),
        );
    }
    let extras: Vec<(usize, &Axis)> = axes
        .iter()
        .enumerate()
        .filter(|(_, a)| matches!(a.role, Role::Extra(_)))
        .collect();
    let extra_hw = match (extras.first(), extras.last()) {
        (Some((j0, _)), Some((j1, _))) => format!(
            "  {words}: joints {j0}-{j1} the same way (stepgen.{j0:02}-{j1:02}), rotaries in degrees\n\
             \x20          (the stepgen's position-scale in steps per degree).\n",
            words = extras
                .iter()
                .map(|(_, a)| a.letter.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        ),
        _ => String::new(),
    };
    let dialect_note = if d.mode == GcodeMode::Linuxcnc {
        String::new()
    } else {
        "\nNOTE: this profile's G-code dialect is not `linuxcnc`: set `[gcode] mode = \"linuxcnc\"`\n\
         in the profile so that galvoplan writes programs for this machine.\n"
            .to_string()
    };
    format!(
        "LinuxCNC configuration for galvoplan profile: {name}
Written by galvoplan {version}.
{dialect_note}
Machine: trivkins, joints 0-{last} = axes {letters}.
{axis_lines}  {u}, {v}: +/-{half} mm (the field), {sv} mm/s, {sa} mm/s^2 (scanner)
Servo period {servo} s. The laser: digital output {n} (motion.digital-out-{n:02}).

Run a program on the simulated machine without a screen (as scripts/check-linuxcnc.sh does):

  mkdir -p /tmp/rtapi && chmod 1777 /tmp/rtapi
  export RTAPI_UID=65534 RTAPI_FIFO_PATH=/tmp/rtapi/.rtapi_fifo   # only when running as root
  GALVOPLAN_PROGRAM=$PWD/job.ngc GALVOPLAN_RESULT=$PWD/job.json linuxcnc galvoplan.ini

galvoplan-run.py resets the machine, homes it in place, runs the program and writes job.json:
ok, errors, and the times (s) from the HAL timers in galvoplan-timers.hal: running_s (the
program), job_s (from the laser's first switch-on to the end: galvoplan's job time), laser_s,
moving_s, laser_on_moving_s. To watch it instead, set DISPLAY = axis in galvoplan.ini.

A real machine (Mesa card with hostmot2): replace the loopback nets in galvoplan.hal with
the card's pins and add its read/write functions to the servo thread, e.g. for a 7i96S:
  stage X: joint.0.motor-pos-cmd => hm2_7i96s.0.stepgen.00.position-cmd,
           joint.0.motor-pos-fb  <= hm2_7i96s.0.stepgen.00.position-fb,
           joint.0.amp-enable-out => hm2_7i96s.0.stepgen.00.enable{y_stepgen};
           servo drives: a pwmgen for the command and an encoder for the feedback, with a pid.
{extra_hw}  scanner {u}/{v} over XY2-100 (firmware with an xy2mod):
           joint.{ju}.motor-pos-cmd => hm2_<board>.0.xy2mod.00.posx-cmd,
           joint.{jv}.motor-pos-cmd => hm2_<board>.0.xy2mod.00.posy-cmd (set posx-scale and
           posy-scale to half the field, {half} mm, so that full scale is the field's edge),
           feedback from posx-fb/posy-fb, enable from amp-enable-out.
  laser:   motion.digital-out-{n:02} => the laser's gate input (a GPIO or sserial output){power}.
Home switches, limits and E-stop wiring are the machine's own; this file homes in place.
{stream}",
        name = profile.name.replace('\n', " "),
        version = env!("CARGO_PKG_VERSION"),
        last = axes.len() - 1,
        y_stepgen = if profile.has_y() { " (Y: stepgen.01)" } else { "" },
        letters = axes
            .iter()
            .map(|a| a.letter.as_str())
            .collect::<Vec<_>>()
            .join(" "),
        u = axes[ju].letter,
        v = axes[jv].letter,
        half = num(profile.field_mm[0].min(profile.field_mm[1]) / 2.0),
        sv = num(axes[ju].velocity_mm_s),
        sa = num(axes[ju].accel_mm_s2),
        servo = num(profile.controller.servo_period_s),
        n = d.laser_output,
        stream = profile.controller.stream_period_s.map_or(String::new(), |p| format!(
            "
Streamed on the fly (galvoplan-stream.hal; docs/GCODE.md): a job planned with
`galvoplan plan ... --stream JOB.stream` runs as JOB.ngc plus its stream, one sample every
{p} s in motmod's base thread (BASE_PERIOD):
  GALVOPLAN_PROGRAM=$PWD/JOB.ngc GALVOPLAN_STREAM=$PWD/JOB.stream \
    GALVOPLAN_RESULT=$PWD/job.json linuxcnc galvoplan.ini
galvoplan-run.py refuses a stream with a sample beyond the axes' limits (the stream bypasses the
soft limits), fills the FIFO, then runs the program: M64 P{sel} hands the joints and the laser to
the stream, M66 P0 waits for its last sample, M65 P{sel} takes them back. An underrun (the FIFO
empty before the last sample) turns the laser off in the same period and is an E-stop.
On a real machine the same wiring holds, with the mux outputs going to the hardware:
  stage X/Y: mux2.0.out / mux2.1.out => the stepgen's position-cmd (hm2_<board>.0.stepgen.00/01)
           or a pid's command for a servo drive (pwmgen + encoder); the base thread's period
           must suit the drive (a stepgen interpolates between servo-rate commands; for a
           stream faster than the servo thread, run the stepgen's update in the base thread or
           keep the stream on the servo period);
  scanner U/V: mux2.2.out / mux2.3.out => hm2_<board>.0.xy2mod.00.posx-cmd / posy-cmd (XY2-100
           takes a position every 10 us: the stream's samples, held between);
  laser:   st-laser-or.out (signal laser-gate) => the laser's gate input, so that an underrun
           switches it off in the same period{power_stream};
  feed the FIFO from user space with halstreamer (as galvoplan-run.py does) or the HAL stream
  API (Python hal.stream), ahead of the consumer; streamer.0.curr-depth shows how far ahead.
",
            sel = stream_output(profile),
            power_stream = if d.power_output.is_some() {
                ";\n  power:   mux2.4.out (signal laser-power) => the laser's analog power input"
            } else {
                ""
            },
        )),
        power = d.power_output.map_or(String::new(), |e| format!(
            "\n  power:   motion.analog-out-{e:02} => the laser's analog power input (a PWM or DAC)"
        )),
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn text(files: &[ConfigFile], name: &str) -> String {
        files
            .iter()
            .find(|f| f.name == name)
            .map(|f| f.text.clone())
            .unwrap_or_default()
    }

    /// The joints' `TYPE`s, in joint order.
    fn types(ini: &str) -> Vec<&str> {
        ini.lines()
            .filter_map(|l| l.strip_prefix("TYPE = "))
            .collect()
    }

    #[test]
    fn a_five_axis_profile_is_a_seven_joint_machine_with_angular_rotaries() {
        let mut p = MachineProfile::builtin("five-axis").unwrap();
        p.gcode.mode = GcodeMode::Linuxcnc;
        let files = linuxcnc_config(&p);
        let ini = text(&files, "galvoplan.ini");
        assert!(
            ini.contains("KINEMATICS = trivkins coordinates=XYZABUV\nJOINTS = 7\n"),
            "{ini}"
        );
        assert!(ini.contains("COORDINATES = XYZABUV\n"));
        assert_eq!(
            types(&ini),
            ["LINEAR", "LINEAR", "LINEAR", "ANGULAR", "ANGULAR", "LINEAR", "LINEAR"]
        );
        // Z from its travel (mm); A and B from theirs, in degrees
        assert!(ini.contains(
            "[AXIS_Z]\nMIN_LIMIT = -150.001\nMAX_LIMIT = 150.001\nMAX_VELOCITY = 218\n\
             MAX_ACCELERATION = 889.795918\n\n[JOINT_2]\nTYPE = LINEAR\n"
        ));
        assert!(ini.contains(
            "[AXIS_A]\nMIN_LIMIT = -110.001\nMAX_LIMIT = 110.001\nMAX_VELOCITY = 121.467053\n\
             MAX_ACCELERATION = 586.797355\n\n[JOINT_3]\nTYPE = ANGULAR\n"
        ));
        assert!(ini.contains("[JOINT_4]\nTYPE = ANGULAR\nMIN_LIMIT = -110.001\nMAX_LIMIT = 110.001\nMAX_VELOCITY = 49.847328\n"));
        assert!(ini.contains("[JOINT_5]\nTYPE = LINEAR\nMIN_LIMIT = -35.001\n"));
        // neither trajectory limit clips an axis: the scanner's speed, the fastest rotary's
        assert!(ini.contains("MAX_LINEAR_VELOCITY = 5000\nDEFAULT_ANGULAR_VELOCITY = 121.467053\nMAX_ANGULAR_VELOCITY = 121.467053\n"));
        let hal = text(&files, "galvoplan.hal");
        for j in 0..7 {
            assert!(hal.contains(&format!(
                "net j{j}-pos joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb\n"
            )));
        }
        assert!(!hal.contains("joint.7"));
        let readme = text(&files, "README.txt");
        assert!(readme.contains("joints 0-6 = axes X Y Z A B U V."));
        assert!(readme.contains("  A: -110.001 .. 110.001 deg, 121.467053 deg/s"));
        assert!(readme.contains("joint.5.motor-pos-cmd => hm2_<board>.0.xy2mod.00.posx-cmd"));
        // an endless rotary: limits far out; a Z whose travel leaves out 0: homed at its end
        p.axis_b.as_mut().unwrap().0.travel = None;
        p.axis_z.as_mut().unwrap().0.travel = Some([10.0, 100.0]);
        let ini = text(&linuxcnc_config(&p), "galvoplan.ini");
        assert!(ini.contains("[AXIS_B]\nMIN_LIMIT = -1000000000\nMAX_LIMIT = 1000000000\n"));
        assert!(ini.contains("[JOINT_2]\nTYPE = LINEAR\nMIN_LIMIT = 9.999\nMAX_LIMIT = 100.001\n"));
        assert!(ini.contains("HOME = 10\nHOME_OFFSET = 10\n"));
    }

    #[test]
    fn a_rotary_machine_without_y_has_no_y_joint() {
        let p = MachineProfile::builtin("rotary").unwrap();
        let files = linuxcnc_config(&p);
        let ini = text(&files, "galvoplan.ini");
        assert!(ini.contains("coordinates=XAUV\nJOINTS = 4\n") && !ini.contains("[AXIS_Y]"));
        assert_eq!(types(&ini), ["LINEAR", "ANGULAR", "LINEAR", "LINEAR"]);
        // endless A
        assert!(ini.contains("[AXIS_A]\nMIN_LIMIT = -1000000000\n"));
        let readme = text(&files, "README.txt");
        assert!(readme.contains("axes X A U V.") && readme.contains("  A: endless, 360 deg/s"));
        assert!(!readme.contains("(Y: stepgen.01)"));
    }

    #[test]
    fn a_flat_profiles_machine_is_xyuv_with_linear_joints() {
        let p = MachineProfile::builtin("linuxcnc").unwrap();
        let files = linuxcnc_config(&p);
        let ini = text(&files, "galvoplan.ini");
        assert!(ini.contains("Stage X/Y, scanner U/V.\n"));
        assert!(ini.contains("coordinates=XYUV\nJOINTS = 4\n"));
        assert_eq!(types(&ini), ["LINEAR"; 4]);
        assert!(ini.contains("MAX_LINEAR_VELOCITY = 5000\n\n[AXIS_X]"));
        assert!(!ini.contains("ANGULAR_VELOCITY"));
        // the stream drives joints 0-3 through mux2.0-3
        let stream = text(&files, "galvoplan-stream.hal");
        assert!(stream.contains(
            "net j3-pos => mux2.3.in0\nnet st-p3 streamer.0.pin.3 => mux2.3.in1\nnet m3-pos mux2.3.out => sampler.0.pin.3\n"
        ));
        assert!(text(&files, "README.txt").contains("joints 0-3 = axes X Y U V.\n  X: -0.001 .. 300.001 mm, 500 mm/s, 5000 mm/s^2 (stage)\n  Y: -0.001 .. 300.001 mm, 500 mm/s, 5000 mm/s^2 (stage)\n  U, V: +/-35 mm (the field)"));
    }
}
