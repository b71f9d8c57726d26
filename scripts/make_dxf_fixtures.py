#!/usr/bin/env python3
"""Writes the DXF test fixtures in tests/data/dxf/ with ezdxf, an independent DXF library, and
next to each drawing the exact geometry ezdxf computes for it (points on every curve, in mm,
y up, inserts exploded), which tests/dxf.rs compares the import with.

    python3 -m venv /tmp/ezdxf-venv && /tmp/ezdxf-venv/bin/pip install ezdxf==1.4.5
    /tmp/ezdxf-venv/bin/python scripts/make_dxf_fixtures.py
"""

import json
import math
import pathlib

import ezdxf
from ezdxf import disassemble
from ezdxf.math import Vec3

OUT = pathlib.Path(__file__).resolve().parent.parent / "tests" / "data" / "dxf"
INCH_MM = 25.4
SAMPLES = 240  # points per curve (the test allows for the chords between them)


def entities_drawing():
    doc = ezdxf.new("R2013")
    doc.header["$INSUNITS"] = 1  # inches
    for name in ("CUT", "ENGRAVE", "BLOCKS"):
        doc.layers.add(name)
    msp = doc.modelspace()
    msp.add_line((0.5, 0.5), (3.0, 0.75), dxfattribs={"layer": "CUT"})
    # a slot: straight sides, semicircular ends (bulge 1), and a shallow arc (bulge 0.25)
    msp.add_lwpolyline(
        [(1.0, 1.5, 0, 0, 0), (2.5, 1.5, 0, 0, 1), (2.5, 2.5, 0, 0, 0), (1.0, 2.5, 0, 0, 1)],
        format="xyseb", close=True, dxfattribs={"layer": "CUT"})
    msp.add_lwpolyline([(4.0, 0.5, -0.25), (6.0, 0.5, 0), (6.0, 1.5, 0)], format="xyb",
                       dxfattribs={"layer": "ENGRAVE"})
    msp.add_circle((5.0, 3.0), 0.75, dxfattribs={"layer": "CUT"})
    msp.add_arc((7.5, 1.0), 0.8, 30, 250, dxfattribs={"layer": "ENGRAVE"})
    msp.add_ellipse((2.0, 4.0), major_axis=(1.2, 0.4), ratio=0.5, dxfattribs={"layer": "CUT"})
    msp.add_ellipse((4.5, 5.0), major_axis=(0.0, 0.8), ratio=0.6, start_param=0.3,
                    end_param=4.0, dxfattribs={"layer": "ENGRAVE"})
    msp.add_open_spline([(6.5, 2.5), (7.0, 3.8), (7.8, 2.2), (8.5, 3.5), (8.8, 2.6)], degree=3,
                        dxfattribs={"layer": "CUT"})
    msp.add_rational_spline([(6.5, 4.0), (7.2, 5.2), (8.2, 4.2), (8.8, 5.0)],
                            weights=[1.0, 3.0, 0.5, 1.0], degree=2, dxfattribs={"layer": "CUT"})
    # nested blocks: INNER (a rounded square and a line) inside OUTER (a circle, two INNERs)
    inner = doc.blocks.new("INNER", base_point=(0.5, 0.5))
    inner.add_lwpolyline([(0, 0, 0), (1, 0, 0.4142), (1, 1, 0), (0, 1, 0)], format="xyb",
                         close=True)
    inner.add_line((0, 0), (1, 1))
    outer = doc.blocks.new("OUTER")
    outer.add_circle((0, 0), 0.3)
    outer.add_blockref("INNER", (0.9, 0.0), dxfattribs={"rotation": 30, "xscale": 0.5,
                                                         "yscale": 0.8})
    outer.add_blockref("INNER", (-0.9, 0.0), dxfattribs={"rotation": -15})
    # uniform outer scale: a non-uniform one would shear the rotated INNERs, which ezdxf's
    # exploding cannot represent exactly (galvoplan maps them exactly, by affine maps)
    msp.add_blockref("OUTER", (2.5, 6.2), dxfattribs={"layer": "BLOCKS", "rotation": 20,
                                                       "xscale": 1.25, "yscale": 1.25})
    # a 3 × 2 array of INNER, scaled and rotated
    arr = msp.add_blockref("INNER", (6.0, 6.0), dxfattribs={"layer": "BLOCKS", "rotation": 10,
                                                            "xscale": 0.4, "yscale": 0.4})
    arr.dxf.column_count = 3
    arr.dxf.row_count = 2
    arr.dxf.column_spacing = 0.7
    arr.dxf.row_spacing = 0.6
    # content without marks: a point (skipped with a warning) and a hatch (not supported)
    msp.add_point((0.2, 0.2))
    hatch = msp.add_hatch()
    hatch.paths.add_polyline_path([(8.0, 0.2), (8.8, 0.2), (8.8, 0.4)])
    return doc


def fit_spline_drawing():
    doc = ezdxf.new("R2018")
    doc.header["$INSUNITS"] = 4  # mm
    fit = [(10, 10), (22, 25), (35, 12), (48, 30), (60, 20)]
    s = doc.modelspace().add_spline(fit)
    s.dxf.layer = "FIT"
    return doc, fit


def text_drawing():
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4  # mm
    doc.styles.add("DEJAVU", font="DejaVuSans.ttf")
    msp = doc.modelspace()
    msp.add_text("SN 0042-ACME", height=5.0,
                 dxfattribs={"style": "DEJAVU", "layer": "TEXT", "insert": (10, 40)})
    msp.add_text("ROT", height=4.0, rotation=90,
                 dxfattribs={"style": "DEJAVU", "layer": "TEXT", "insert": (80, 20)})
    msp.add_mtext("LOT 7\\PBATCH 12", dxfattribs={"style": "DEJAVU", "layer": "MTEXT",
                                                 "char_height": 3.0, "insert": (10, 25),
                                                 "attachment_point": 1})
    return doc


def exact_points(doc):
    """Points on every marked curve in mm (inserts exploded by ezdxf), one list per primitive."""
    scale = INCH_MM if doc.header.get("$INSUNITS", 0) == 1 else 1.0
    curves = []
    for e in disassemble.recursive_decompose(doc.modelspace()):
        kind = e.dxftype()
        pts = []
        if kind == "LINE":
            a, b = Vec3(e.dxf.start), Vec3(e.dxf.end)
            pts = [a.lerp(b, i / 20) for i in range(21)]
        elif kind == "CIRCLE":
            pts = list(e.vertices([i * 360 / SAMPLES for i in range(SAMPLES + 1)]))
        elif kind == "ARC":
            sweep = (e.dxf.end_angle - e.dxf.start_angle) % 360 or 360
            pts = list(e.vertices([e.dxf.start_angle + sweep * i / SAMPLES
                                   for i in range(SAMPLES + 1)]))
        elif kind == "ELLIPSE":
            ce = e.construction_tool()
            span = (ce.end_param - ce.start_param) % math.tau or math.tau
            pts = list(ce.vertices([ce.start_param + span * i / SAMPLES
                                    for i in range(SAMPLES + 1)]))
        elif kind == "SPLINE":
            bs = e.construction_tool()
            pts = list(bs.points([bs.max_t * i / SAMPLES for i in range(SAMPLES + 1)]))
        elif kind == "LWPOLYLINE":
            for ve in e.virtual_entities():
                curves.extend(exact_points_of_virtual(ve, scale))
            continue
        else:
            continue
        curves.append([[p.x * scale, p.y * scale] for p in pts])
    return curves


def exact_points_of_virtual(e, scale):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 1 if scale == INCH_MM else 4
    doc.modelspace().add_entity(e.copy())
    return exact_points(doc)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    doc = entities_drawing()
    doc.saveas(OUT / "entities-inch.dxf")
    (OUT / "entities-inch.exact.json").write_text(json.dumps(
        {"units_mm": INCH_MM, "curves": [[[round(v, 6) for v in p] for p in c]
                                         for c in exact_points(doc)]}, separators=(",", ":")))
    fit_doc, fit = fit_spline_drawing()
    fit_doc.saveas(OUT / "fit-spline-r2018.dxf")
    (OUT / "fit-spline-r2018.fit.json").write_text(json.dumps(fit))
    text_drawing().saveas(OUT / "text.dxf")


if __name__ == "__main__":
    main()
