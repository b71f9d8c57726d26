//! Placement of the imported artwork on the machine (`--place`), the same for SVG and DXF.
//!
//! The default, [`Place::Auto`], keeps the file's coordinates wherever the laser reaches the
//! whole artwork (an SVG's page coordinates, a DXF's own coordinates), so jobs that plan today
//! plan the same; artwork out of reach that would fit the reach is centred on the base stroke,
//! with a warning. [`Place::AsIs`], [`Place::Centre`] and [`Place::Corner`] are the operator's
//! explicit choices.

use super::{ImportOptions, Imported, Warning};
use crate::document::{Place, PlaceError};
use crate::geom::{BBox, Pt};

/// Offsets and moved coordinates are rounded to a grid of 1 / this many mm, the import's own
/// 10 nm (see `svg::SNAP_MM`), so that round coordinates stay round after a move.
const GRID_PER_MM: f64 = 1e5;
/// Slack of the reach test (mm), as the field stage's (`fields::INSIDE_EPS_MM`).
const REACH_EPS_MM: f64 = 1e-7;

/// The box of machine positions the laser reaches: the work area grown by half a field on every
/// side (`None` without a work area).
fn reach_box(opts: &ImportOptions) -> Option<BBox> {
    let [sw, sh] = opts.work_area_mm?;
    let [fw, fh] = opts.field_mm.unwrap_or([0.0, 0.0]);
    Some(BBox {
        min_x: -fw / 2.0,
        min_y: -fh / 2.0,
        max_x: sw + fw / 2.0,
        max_y: sh + fh / 2.0,
    })
}

fn inside(b: &BBox, r: &BBox) -> bool {
    b.min_x >= r.min_x - REACH_EPS_MM
        && b.min_y >= r.min_y - REACH_EPS_MM
        && b.max_x <= r.max_x + REACH_EPS_MM
        && b.max_y <= r.max_y + REACH_EPS_MM
}

/// Decimals that show an offset of `resolution_mm` (4 for 10⁻⁴ mm).
fn decimals(resolution_mm: f64) -> usize {
    if resolution_mm > 0.0 && resolution_mm.is_finite() {
        (-resolution_mm.log10()).ceil().clamp(0.0, 9.0) as usize
    } else {
        4
    }
}

/// An offset component rounded to the import's grid; zero when below the export's resolution.
fn offset(d: f64, resolution_mm: f64) -> f64 {
    if d.abs() < resolution_mm {
        0.0
    } else {
        on_grid(d)
    }
}

/// `v` on the import's grid (the nearest `f64` to a multiple of 10 nm).
fn on_grid(v: f64) -> f64 {
    (v * GRID_PER_MM).round() / GRID_PER_MM
}

/// Places the imported geometries as `opts.place` says (see [`Place`]), moving them together;
/// offsets below `opts.resolution_mm` are neither applied nor reported. After a move the page
/// is the work area (its corner at the origin, so a profile's G-code Y flip mirrors about the
/// stroke's height); without a work area it grows to hold the moved artwork. Sets
/// `im.moved_mm`; [`Place::Auto`] adds a warning when it moves the artwork.
pub fn place_artwork(im: &mut Imported, opts: &ImportOptions) -> Result<(), PlaceError> {
    im.moved_mm = [0.0, 0.0];
    let b = im
        .geometries
        .iter()
        .fold(BBox::EMPTY, |b, g| b.union(BBox::of(&g.points)));
    if b.is_empty() {
        return Ok(());
    }
    let centre_of = |[sw, sh]: [f64; 2]| {
        [
            sw / 2.0 - (b.min_x + b.max_x) / 2.0,
            sh / 2.0 - (b.min_y + b.max_y) / 2.0,
        ]
    };
    let mut auto_moved = false;
    let wanted = match opts.place {
        Place::AsIs => None,
        Place::Centre => Some(centre_of(opts.work_area_mm.ok_or(PlaceError::NoWorkArea)?)),
        Place::Corner([x, y]) => Some([x - b.min_x, y - b.min_y]),
        Place::Auto => match (opts.work_area_mm, reach_box(opts)) {
            (Some(area), Some(r))
                if !inside(&b, &r) && b.width() <= r.width() && b.height() <= r.height() =>
            {
                auto_moved = true;
                Some(centre_of(area))
            }
            _ => None,
        },
    };
    let Some([dx, dy]) = wanted else {
        return Ok(());
    };
    let (dx, dy) = (
        offset(dx, opts.resolution_mm),
        offset(dy, opts.resolution_mm),
    );
    if dx == 0.0 && dy == 0.0 {
        return Ok(());
    }
    for g in &mut im.geometries {
        for p in &mut g.points {
            *p = Pt::new(on_grid(p.x + dx), on_grid(p.y + dy));
        }
    }
    im.moved_mm = [dx, dy];
    im.page_mm = match opts.work_area_mm {
        Some(area) => area,
        None => [
            im.page_mm[0].max(b.max_x + dx),
            im.page_mm[1].max(b.max_y + dy),
        ],
    };
    if auto_moved {
        let n = decimals(opts.resolution_mm);
        let r = reach_box(opts).unwrap_or(b);
        im.warnings.push(Warning {
            element: "artwork".into(),
            line: None,
            message: format!(
                "lies out of reach where the file puts it (x {:.1}…{:.1}, y {:.1}…{:.1} mm; the \
                 laser reaches x {:.1}…{:.1}, y {:.1}…{:.1} mm): centred on the base stroke, moved \
                 by ({}, {}) mm",
                b.min_x,
                b.max_x,
                b.min_y,
                b.max_y,
                r.min_x,
                r.max_x,
                r.min_y,
                r.max_y,
                crate::geom::format_mm(dx, n),
                crate::geom::format_mm(dy, n)
            ),
            note: false,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Geometry;

    fn square(x: f64, y: f64, side: f64) -> Geometry {
        crate::fields::tests_support::rect(x, y, side, side)
    }

    fn machine(place: Place) -> ImportOptions {
        ImportOptions {
            work_area_mm: Some([300.0, 300.0]),
            field_mm: Some([70.0, 70.0]),
            place,
            ..ImportOptions::default()
        }
    }

    fn imported(g: Vec<Geometry>) -> Imported {
        Imported {
            geometries: g,
            page_mm: [400.0, 400.0],
            ..Imported::default()
        }
    }

    #[test]
    fn parses_every_placement_and_refuses_nonsense() {
        assert_eq!("as-is".parse(), Ok(Place::AsIs));
        assert_eq!("Centre".parse(), Ok(Place::Centre));
        assert_eq!("center".parse(), Ok(Place::Centre));
        assert_eq!("auto".parse(), Ok(Place::Auto));
        assert_eq!("corner:10,-5.5".parse(), Ok(Place::Corner([10.0, -5.5])));
        for bad in [
            "",
            "corner:",
            "corner:1",
            "corner:a,b",
            "corner:inf,0",
            "middle",
        ] {
            assert!(bad.parse::<Place>().is_err(), "{bad}");
        }
        for p in [
            Place::AsIs,
            Place::Centre,
            Place::Auto,
            Place::Corner([1.5, 2.0]),
        ] {
            assert_eq!(p.to_string().parse(), Ok(p));
        }
    }

    #[test]
    fn auto_keeps_artwork_in_reach_and_centres_what_fits() {
        // in reach (the reach is -35…335): stays, no warning, page unchanged
        let mut im = imported(vec![square(-30.0, 300.0, 30.0)]);
        place_artwork(&mut im, &machine(Place::Auto)).unwrap();
        assert_eq!(im.geometries[0].points[0], Pt::new(-30.0, 300.0));
        assert_eq!((im.moved_mm, im.page_mm), ([0.0, 0.0], [400.0, 400.0]));
        assert!(im.warnings.is_empty());
        // 6 mm beyond the reach, small enough: centred, with a warning naming the offset
        let mut im = imported(vec![square(10.0, 10.0, 331.0)]);
        place_artwork(&mut im, &machine(Place::Auto)).unwrap();
        assert_eq!(im.moved_mm, [-25.5, -25.5]);
        assert_eq!(im.geometries[0].points[0], Pt::new(-15.5, -15.5));
        assert_eq!(im.page_mm, [300.0, 300.0]);
        assert_eq!(im.warnings.len(), 1);
        assert!(
            im.warnings[0]
                .message
                .contains("moved by (-25.5, -25.5) mm"),
            "{}",
            im.warnings[0]
        );
        // larger than the reach: left as it is for the field stage to refuse
        let mut im = imported(vec![square(0.0, 0.0, 371.0)]);
        place_artwork(&mut im, &machine(Place::Auto)).unwrap();
        assert_eq!(im.moved_mm, [0.0, 0.0]);
        assert!(im.warnings.is_empty());
    }

    #[test]
    fn explicit_placements_move_without_warning_and_tiny_offsets_are_not_made() {
        let mut im = imported(vec![square(10.0, 20.0, 50.0)]);
        place_artwork(&mut im, &machine(Place::Centre)).unwrap();
        assert_eq!(im.geometries[0].points[0], Pt::new(125.0, 125.0));
        assert!(im.warnings.is_empty());
        let mut im = imported(vec![square(10.0, 20.0, 50.0)]);
        place_artwork(&mut im, &machine(Place::Corner([0.0, 5.0]))).unwrap();
        assert_eq!(im.geometries[0].points[0], Pt::new(0.0, 5.0));
        assert_eq!(im.moved_mm, [-10.0, -15.0]);
        // 2 µm off the centre: below the 0.1 µm resolution? no: 2 µm is moved
        let mut im = imported(vec![square(125.002, 125.0, 50.0)]);
        place_artwork(&mut im, &machine(Place::Centre)).unwrap();
        assert!((im.moved_mm[0] + 0.002).abs() < 1e-12 && im.moved_mm[1] == 0.0);
        // 20 nm off: below the export's resolution, nothing moves
        let mut im = imported(vec![square(125.00002, 125.0, 50.0)]);
        place_artwork(&mut im, &machine(Place::Centre)).unwrap();
        assert_eq!(im.moved_mm, [0.0, 0.0]);
        assert_eq!(im.page_mm, [400.0, 400.0]);
        // centring without a machine is refused
        let mut im = imported(vec![square(0.0, 0.0, 5.0)]);
        let no_machine = ImportOptions {
            place: Place::Centre,
            ..ImportOptions::default()
        };
        assert_eq!(
            place_artwork(&mut im, &no_machine),
            Err(PlaceError::NoWorkArea)
        );
    }
}
