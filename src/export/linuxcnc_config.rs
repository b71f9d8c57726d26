//! A LinuxCNC machine configuration from a machine profile (docs/GCODE.md, *LinuxCNC*):
//! `galvoplan linuxcnc-config --profile P.toml --out DIR`.
//!
//! One trivkins machine with four joints, X and Y for the stage and the profile's two scanner
//! axis words (default U, V) for the scanner, with the profile's stroke, field, speeds and
//! accelerations as limits, and a digital output for the laser. The files:
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

use crate::document::{GcodeMode, MachineProfile};
use std::fmt::Write;

/// Headroom added to every axis limit, mm: positions written with the dialect's decimals may
/// round past a limit by half a unit of the last place.
pub const LIMIT_MARGIN_MM: f64 = 0.001;

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

/// One axis of the configuration.
struct Axis {
    letter: String,
    min_mm: f64,
    max_mm: f64,
    velocity_mm_s: f64,
    accel_mm_s2: f64,
}

/// The configuration files for `profile` (see the module documentation).
pub fn linuxcnc_config(profile: &MachineProfile) -> Vec<ConfigFile> {
    let axes = axes(profile);
    vec![
        ConfigFile {
            name: "galvoplan.ini",
            text: ini(profile, &axes),
            executable: false,
        },
        ConfigFile {
            name: "galvoplan.hal",
            text: hal(profile),
            executable: false,
        },
        ConfigFile {
            name: "galvoplan-timers.hal",
            text: TIMERS_HAL.to_string(),
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
    ]
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
        min_mm: -LIMIT_MARGIN_MM,
        max_mm: profile.stroke_mm[k] + LIMIT_MARGIN_MM,
        velocity_mm_s: limits.max_velocity_mm_s,
        accel_mm_s2: limits.max_accel_mm_s2,
    };
    let scanner = |k: usize| Axis {
        letter: words[k].trim().to_uppercase(),
        min_mm: -half(k),
        max_mm: half(k),
        velocity_mm_s: scanner_velocity,
        accel_mm_s2: profile.controller.scanner_accel_mm_s2,
    };
    vec![
        stage("X", 0, &profile.axis_x),
        stage("Y", 1, &profile.axis_y),
        scanner(0),
        scanner(1),
    ]
}

fn num(v: f64) -> String {
    crate::geom::format_mm(v, 6)
}

fn ini(profile: &MachineProfile, axes: &[Axis]) -> String {
    let coords: String = axes.iter().map(|a| a.letter.as_str()).collect();
    let servo_ns = (profile.controller.servo_period_s * 1e9).round() as u64;
    let fastest = axes.iter().map(|a| a.velocity_mm_s).fold(0.0, f64::max);
    let mut s = String::new();
    let _ = write!(
        s,
        "# LinuxCNC machine for galvoplan profile: {name}
# Written by galvoplan {version} (galvoplan linuxcnc-config). Stage X/Y, scanner {u}/{v}.

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

[EMCIO]
EMCIO = io
CYCLE_TIME = 0.100
TOOL_TABLE = galvoplan.tbl

[HAL]
HALUI = halui
HALFILE = galvoplan.hal
HALFILE = galvoplan-timers.hal

[KINS]
KINEMATICS = trivkins coordinates={coords}
JOINTS = 4

[TRAJ]
COORDINATES = {coords}
LINEAR_UNITS = mm
ANGULAR_UNITS = degree
DEFAULT_LINEAR_VELOCITY = {default_v}
MAX_LINEAR_VELOCITY = {fastest}
",
        name = profile.name.replace('\n', " "),
        name_short = profile.name.split(" (").next().unwrap_or("machine"),
        version = env!("CARGO_PKG_VERSION"),
        u = axes[2].letter,
        v = axes[3].letter,
        default_v = num(profile.axis_x.max_velocity_mm_s),
        fastest = num(fastest),
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
            "\n[AXIS_{l}]\n{limits}\n[JOINT_{j}]\nTYPE = LINEAR\n{limits}FERROR = 1\nMIN_FERROR = 1\n\
             HOME = 0\nHOME_OFFSET = 0\nHOME_SEARCH_VEL = 0\nHOME_LATCH_VEL = 0\nHOME_SEQUENCE = 0\n",
            l = a.letter
        );
    }
    s
}

fn hal(profile: &MachineProfile) -> String {
    let d = &profile.gcode;
    let dio = (d.laser_output + 1).max(4);
    let aio = d.power_output.map_or(4, |e| (e + 1).max(4));
    let mut s = format!(
        "# Motion and the simulated machine (galvoplan linuxcnc-config).
loadrt [KINS]KINEMATICS
loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS num_dio={dio} num_aio={aio}
addf motion-command-handler servo-thread
addf motion-controller servo-thread

# Simulated machine: each joint's command is its feedback. On a real machine these lines go
# (README.txt): the stage joints to a stepgen or PWM + encoder, the scanner joints to an XY2-100
# module.
"
    );
    for j in 0..4 {
        let _ = writeln!(
            s,
            "net j{j}-pos joint.{j}.motor-pos-cmd => joint.{j}.motor-pos-fb"
        );
    }
    let _ = write!(
        s,
        "
net estop-loop iocontrol.0.user-enable-out => iocontrol.0.emc-enable-in
net tool-prep-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared
net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed

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
Machine: trivkins, joints 0-3 = axes {x} {y} {u} {v}.
  {x}: {x0} .. {x1} mm, {xv} mm/s, {xa} mm/s^2 (stage)
  {y}: {y0} .. {y1} mm, {yv} mm/s, {ya} mm/s^2 (stage)
  {u}, {v}: +/-{half} mm (the field), {sv} mm/s, {sa} mm/s^2 (scanner)
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
           joint.0.amp-enable-out => hm2_7i96s.0.stepgen.00.enable (Y: stepgen.01);
           servo drives: a pwmgen for the command and an encoder for the feedback, with a pid.
  scanner {u}/{v} over XY2-100 (firmware with an xy2mod):
           joint.2.motor-pos-cmd => hm2_<board>.0.xy2mod.00.posx-cmd,
           joint.3.motor-pos-cmd => hm2_<board>.0.xy2mod.00.posy-cmd (set posx-scale and
           posy-scale to half the field, {half} mm, so that full scale is the field's edge),
           feedback from posx-fb/posy-fb, enable from amp-enable-out.
  laser:   motion.digital-out-{n:02} => the laser's gate input (a GPIO or sserial output){power}.
Home switches, limits and E-stop wiring are the machine's own; this file homes in place.
",
        name = profile.name.replace('\n', " "),
        version = env!("CARGO_PKG_VERSION"),
        x = axes[0].letter,
        y = axes[1].letter,
        u = axes[2].letter,
        v = axes[3].letter,
        x0 = num(axes[0].min_mm),
        x1 = num(axes[0].max_mm),
        xv = num(axes[0].velocity_mm_s),
        xa = num(axes[0].accel_mm_s2),
        y0 = num(axes[1].min_mm),
        y1 = num(axes[1].max_mm),
        yv = num(axes[1].velocity_mm_s),
        ya = num(axes[1].accel_mm_s2),
        half = num(profile.field_mm[0].min(profile.field_mm[1]) / 2.0),
        sv = num(axes[2].velocity_mm_s),
        sa = num(axes[2].accel_mm_s2),
        servo = num(profile.controller.servo_period_s),
        n = d.laser_output,
        power = d.power_output.map_or(String::new(), |e| format!(
            "\n  power:   motion.analog-out-{e:02} => the laser's analog power input (a PWM or DAC)"
        )),
    )
}
