//! Cylinder jobs: every mark of the program mapped back onto the cylinder lands on the drawing
//! (within 0.02 mm, everything marked, nothing twice, all in focus, across the wrap line), and
//! bad input in one line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{galvoplan, one_line_error};

use galvoplan::document::{Cylinder, Geometry, MachineProfile, SolverSettings};
use galvoplan::geom::{point_segment_dist, Pt};
use galvoplan::import::ImportOptions;
use galvoplan::job::JobCtx;
use galvoplan::pipeline::{load_artwork, plan_document_lowered};

/// How far a landed mark may lie from the drawing, mm (the acceptance's figure).
const LAND_TOL_MM: f64 = 0.02;

/// A program's marks, mapped back onto the unrolled surface: each `G1` with the laser on,
/// sampled along the move (not only at its ends): axial = X + U, arc = R·(A·π/180 + asin(V/R)).
/// Also the largest defocus met, mm.
fn landed_marks(gcode: &str, radius: f64) -> (Vec<Vec<Pt>>, f64) {
    let (mut x, mut a, mut u, mut v) = (0.0, 0.0, 0.0, 0.0);
    let mut on = false;
    let mut marks: Vec<Vec<Pt>> = Vec::new();
    let mut defocus: f64 = 0.0;
    let land = |x: f64, a: f64, u: f64, v: f64| {
        let arc = radius * (a.to_radians() + (v / radius).asin());
        Pt::new(x + u, arc)
    };
    for line in gcode.lines() {
        let line = line.split(';').next().unwrap().trim();
        let mut words = line.split_whitespace();
        let Some(cmd) = words.next() else { continue };
        let mut next = (x, a, u, v);
        for w in words {
            let (k, val) = w.split_at(1);
            let Ok(val) = val.parse::<f64>() else {
                continue;
            };
            match k {
                "X" => next.0 = val,
                "A" => next.1 = val,
                "U" => next.2 = val,
                "V" => next.3 = val,
                _ => {}
            }
        }
        match cmd {
            "M3" => {
                on = true;
                marks.push(vec![land(x, a, u, v)]);
            }
            "M5" => on = false,
            "G1" if on => {
                assert_eq!(
                    (next.0, next.1),
                    (x, a),
                    "the stage moves while marking: {line}"
                );
                for k in 1..=20 {
                    let t = f64::from(k) / 20.0;
                    let (su, sv) = (u + t * (next.2 - u), v + t * (next.3 - v));
                    let phi = (sv / radius).asin();
                    defocus = defocus.max(radius * (1.0 - phi.cos()));
                    marks.last_mut().unwrap().push(land(x, a, su, sv));
                }
            }
            _ => {}
        }
        (x, a, u, v) = next;
    }
    (marks, defocus)
}

/// Distance on the surface from `p` to the polyline `path`: the same surface point a turn
/// before or after counts (a drawing across the wrap line, marks turned beyond 360°). Paths
/// whose box lies further than 1 mm are at least that far.
fn dist_to(p: Pt, path: &[Pt], circumference: f64) -> f64 {
    let (x0, x1) = path
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.x), b.max(q.x))
        });
    let (y0, y1) = path
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.y), b.max(q.y))
        });
    [-2.0, -1.0, 0.0, 1.0, 2.0]
        .into_iter()
        .map(|turns| {
            let q = Pt::new(p.x, p.y + turns * circumference);
            if q.x < x0 - 1.0 || q.x > x1 + 1.0 || q.y < y0 - 1.0 || q.y > y1 + 1.0 {
                return 1.0;
            }
            if path.len() == 1 {
                return q.dist(path[0]);
            }
            path.windows(2)
                .map(|w| point_segment_dist(q, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min)
}

fn polyline(g: &Geometry) -> Vec<Pt> {
    let mut p = g.points.clone();
    if g.closed {
        p.push(g.points[0]);
    }
    p
}

fn length(p: &[Pt]) -> f64 {
    p.windows(2).map(|w| w[0].dist(w[1])).sum()
}

/// Plans `svg` around a cylinder of `diameter` on the rotary machine, writes its program and
/// checks that every mark lands on the drawing, covers it once, and stays in focus.
fn marks_land_on_the_drawing(svg: &std::path::Path, diameter: f64) {
    let profile = MachineProfile::builtin("rotary").unwrap();
    let dof = profile.scanner.depth_of_focus_mm.unwrap();
    let settings = SolverSettings {
        cylinder: Some(Cylinder {
            diameter_mm: diameter,
        }),
        ..SolverSettings::default()
    };
    let mut doc = load_artwork(svg, profile, settings, &ImportOptions::default())
        .unwrap()
        .doc;
    let (plan, toolpath) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
    assert!(plan.fields.len() > 3, "{} strips", plan.fields.len());
    // the geometries were made for the strips: made again from outside the solve (the GUI's
    // layer edits), nothing changes
    let fields = doc.fields.clone();
    let again = galvoplan::pipeline::derive_geometries(&mut doc, &JobCtx::default()).unwrap();
    assert_eq!((again, &doc.fields), (0.0, &fields));
    let gcode = galvoplan::export::write_gcode(&toolpath, &plan, doc.page_mm[1], "t").unwrap();
    let c = Cylinder {
        diameter_mm: diameter,
    };
    let (r, around) = (c.radius_mm(), c.circumference_mm());
    let (marks, defocus) = landed_marks(&gcode, r);
    assert!(defocus <= dof + 1e-9, "a mark {defocus} mm below the focus");
    let drawing: Vec<Vec<Pt>> = doc.artwork.iter().map(polyline).collect();
    // within 0.02 mm everywhere
    let mut worst: f64 = 0.0;
    for m in &marks {
        for &p in m {
            let d = drawing
                .iter()
                .map(|g| dist_to(p, g, around))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    assert!(
        worst <= LAND_TOL_MM,
        "a mark lands {worst} mm from the drawing"
    );
    // nothing unmarked: every 0.1 mm of the drawing lies on a mark
    let mut uncovered: f64 = 0.0;
    for g in &drawing {
        for w in g.windows(2) {
            let n = (w[0].dist(w[1]) / 0.1).ceil().max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                let p = Pt::new(
                    w[0].x + t * (w[1].x - w[0].x),
                    w[0].y + t * (w[1].y - w[0].y),
                );
                let d = marks
                    .iter()
                    .map(|m| dist_to(p, m, around))
                    .fold(f64::INFINITY, f64::min);
                uncovered = uncovered.max(d);
            }
        }
    }
    assert!(
        uncovered <= LAND_TOL_MM,
        "the drawing is {uncovered} mm from any mark"
    );
    // nothing twice: the marks are as long as the drawing (covered, so no part twice)
    let (marked, drawn): (f64, f64) = (
        marks.iter().map(|m| length(m)).sum(),
        drawing.iter().map(|g| length(g)).sum(),
    );
    assert!(
        (marked / drawn - 1.0).abs() < 1e-3,
        "marked {marked} mm of a {drawn} mm drawing"
    );
}

#[test]
fn every_mark_of_a_sleeve_lands_where_the_drawing_says() {
    let svg = common::root().join("assets/examples/sleeve.svg");
    marks_land_on_the_drawing(&svg, 40.0);
}

#[test]
fn a_drawing_across_the_wrap_line_is_marked_without_a_gap_or_a_double_mark() {
    // ⌀40 mm: the circumference 125.66 mm; the drawing runs from arc 100 to 140 mm
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("wrap.svg");
    std::fs::write(
        &svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="160mm" viewBox="0 0 100 160">
<g fill="none" stroke="#000000" stroke-width="0.1">
<line x1="10" y1="100" x2="60" y2="140"/>
<line x1="30" y1="101" x2="30" y2="139"/>
<rect x="40" y="118" width="20" height="15"/>
<circle cx="75" cy="125.66" r="6"/>
</g></svg>"##,
    )
    .unwrap();
    marks_land_on_the_drawing(&svg, 40.0);
}

/// On a machine whose rotary is slow against X, ordering on job time turns the part less: never
/// slower than ordering on the distance between strips on the surface.
#[test]
fn the_time_order_is_never_slower_than_the_distance_order_on_a_slow_rotary() {
    let profile = MachineProfile::load(
        &common::root()
            .join("tests/data/profiles/slow-rotary.toml")
            .display()
            .to_string(),
    )
    .unwrap();
    let svg = common::root().join("assets/examples/demo.svg");
    let time = |cost| {
        let settings = SolverSettings {
            cylinder: Some(Cylinder { diameter_mm: 100.0 }),
            cost_model: cost,
            ..SolverSettings::default()
        };
        let mut doc = load_artwork(&svg, profile.clone(), settings, &ImportOptions::default())
            .unwrap()
            .doc;
        let (plan, _) = plan_document_lowered(&mut doc, &JobCtx::default()).unwrap();
        assert!(plan.fields.len() > 20, "{} strips", plan.fields.len());
        plan.metrics.job_time_s.unwrap()
    };
    let (t, d) = (
        time(galvoplan::document::CostModel::Time),
        time(galvoplan::document::CostModel::Distance),
    );
    assert!(t <= d * 1.001, "by time {t} s, by distance {d} s");
}

/// A tray of parts with their serials and a DataMatrix each, hatched, around a cylinder: planned
/// as on a flat job, every part in the report, every strip posed.
#[test]
fn trays_codes_and_hatch_work_around_a_cylinder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.ngc").display().to_string();
    let report = dir.path().join("t.json").display().to_string();
    let part = common::root()
        .join("assets/examples/part.svg")
        .display()
        .to_string();
    let o = galvoplan(&[
        "plan",
        &part,
        "--profile",
        "rotary",
        "--cylinder",
        "60",
        "--array",
        "2x2@40,32",
        "--serial",
        "1001",
        "--code",
        "datamatrix:GP{serial:05}@3,3:6",
        "--hatch",
        "lines:0.1",
        "-o",
        &out,
        "--report",
        &report,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // the cuts at the strips' borders in one line
    let said = String::from_utf8_lossy(&o.stderr);
    let cuts: Vec<&str> = said.lines().filter(|l| l.contains("cut at")).collect();
    assert_eq!(cuts.len(), 1, "{said}");
    assert!(
        cuts[0].contains("taller than a strip in focus")
            && cuts[0].contains("are cut at the strips' borders"),
        "{said}"
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["parts"].as_array().unwrap().len(), 4);
    assert_eq!(r["cylinder"]["diameter_mm"], 60.0);
    for f in r["fields"].as_array().unwrap() {
        let (y, a) = (
            f["center"][1].as_f64().unwrap(),
            f["pose"]["a_deg"].as_f64().unwrap(),
        );
        assert!((a - (y / 30.0).to_degrees()).abs() < 1e-9, "{f}");
    }
    let gcode = std::fs::read_to_string(&out).unwrap();
    assert!(gcode
        .lines()
        .any(|l| l.starts_with("G0 X") && l.contains(" A")));
}

/// A cylinder job saved as a project stays one: `plan` of the project (without `--cylinder`)
/// marks its strips around the cylinder, where the drawing says.
#[test]
fn a_saved_cylinder_job_plans_around_its_cylinder() {
    let dir = tempfile::tempdir().unwrap();
    let svg = common::root().join("assets/examples/sleeve.svg");
    let settings = SolverSettings {
        cylinder: Some(Cylinder { diameter_mm: 40.0 }),
        ..SolverSettings::default()
    };
    let rotary = MachineProfile::builtin("rotary").unwrap();
    let mut doc = load_artwork(&svg, rotary, settings, &ImportOptions::default())
        .unwrap()
        .doc;
    galvoplan::pipeline::place_document_fields(&mut doc, &JobCtx::default()).unwrap();
    let project = dir.path().join("sleeve.galvoplan");
    galvoplan::document::save_project(&doc, &project).unwrap();
    let out = dir.path().join("p.ngc");
    let o = galvoplan(&[
        "plan",
        &project.display().to_string(),
        "-o",
        &out.display().to_string(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let gcode = std::fs::read_to_string(&out).unwrap();
    let (marks, defocus) = landed_marks(&gcode, 20.0);
    assert!(defocus <= 0.8 + 1e-9);
    let drawing: Vec<Vec<Pt>> = doc.artwork.iter().map(polyline).collect();
    let c = Cylinder { diameter_mm: 40.0 }.circumference_mm();
    for p in marks.iter().flatten() {
        let d = drawing
            .iter()
            .map(|g| dist_to(*p, g, c))
            .fold(f64::INFINITY, f64::min);
        assert!(d <= LAND_TOL_MM, "{p:?} lands {d} mm from the drawing");
    }
}

#[test]
fn bad_cylinder_jobs_say_why_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.ngc").display().to_string();
    let sleeve = common::root()
        .join("assets/examples/sleeve.svg")
        .display()
        .to_string();
    // `plan INPUT ARGS -o out`, refused in one line
    let refused = |input: &str, args: &[&str]| {
        let mut all = vec!["plan", input];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", &out]);
        one_line_error(&galvoplan(&all))
    };
    // taller than the circumference: 110 mm on ⌀30 (94.25 mm)
    let e = refused(&sleeve, &["--profile", "rotary", "--cylinder", "30"]);
    assert!(e.contains("more than its circumference 94.25 mm"), "{e}");
    // a flat job on a machine that turns the part: the cylinder is the way
    let e = refused(&sleeve, &["--profile", "rotary"]);
    assert!(
        e.contains("use --cylinder DIAMETER_MM to mark around it"),
        "{e}"
    );
    // no A axis
    let e = refused(&sleeve, &["--cylinder", "40"]);
    assert!(e.contains("needs an A axis"), "{e}");
    // a DOF of zero
    let zero = dir.path().join("zero.toml");
    std::fs::write(&zero, "version = 5\n[scanner]\ndepth_of_focus_mm = 0.0\n").unwrap();
    let zero = zero.display().to_string();
    let e = refused(&sleeve, &["--profile", &zero, "--cylinder", "40"]);
    assert!(
        e.contains("Depth of focus (mm) must be a positive number, not 0"),
        "{e}"
    );
    // strips thinner than the spot: a 0.01 µm DOF on ⌀1 mm
    let thin = dir.path().join("thin.toml");
    let rotary = std::fs::read_to_string(common::root().join("assets/profiles/rotary.toml"))
        .unwrap()
        .replace("depth_of_focus_mm = 0.8", "depth_of_focus_mm = 0.00001");
    std::fs::write(&thin, rotary).unwrap();
    let small = dir.path().join("small.svg");
    std::fs::write(
        &small,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="3mm" viewBox="0 0 10 3"><line x1="1" y1="1" x2="5" y2="2" stroke="#000"/></svg>"##,
    )
    .unwrap();
    let (small, thin) = (small.display().to_string(), thin.display().to_string());
    let e = refused(&small, &["--profile", &thin, "--cylinder", "1"]);
    assert!(e.contains("thinner than the"), "{e}");
    // not a diameter
    let e = refused(&sleeve, &["--profile", "rotary", "--cylinder=-3"]);
    assert!(
        e.contains("Cylinder diameter (mm) must be a positive number")
            && e.contains("(--cylinder)"),
        "{e}"
    );
    // on the fly
    let e = refused(
        &sleeve,
        &[
            "--profile",
            "rotary",
            "--cylinder",
            "40",
            "--motion",
            "on-the-fly",
        ],
    );
    assert!(e.contains("step-and-scan"), "{e}");
}
