#!/usr/bin/env python3
"""Writes the IES LM-63 test files of this folder from closed forms (run from this folder).

Each distribution's flux is known exactly: an isotropic I over the sphere gives 4 pi I lm,
I0 cos(theta) over the lower hemisphere gives pi I0 lm, and the horizontal factors
(1 + a cos 2phi), (1 + a cos phi), (1 + a sin phi) integrate to 2 pi over a turn, so each
file's stated lumens is that closed form. The symmetric files hold the same values as the
full ones over their part of the turn (computed once and mirrored), so a reader that expands
symmetry by the standard gives the same candela everywhere.
"""
import math


def fmt(x):
    return f"{x:.6f}".rstrip("0").rstrip(".") if x != int(x) else str(int(x))


def rows(values, per_line=10, sep=" "):
    out = []
    for i in range(0, len(values), per_line):
        out.append(sep.join(fmt(v) for v in values[i:i + per_line]))
    return "\n".join(out)


def write(name, header, lamps, lumens, multiplier, vert, horiz, table, ballast=1.0,
          third=1.0, units=2, dims=(0, 0, 0), watts=10.0, tilt="TILT=NONE", sep=" "):
    text = header.rstrip("\n") + "\n" + tilt + "\n"
    text += f"{lamps} {fmt(lumens)} {fmt(multiplier)} {len(vert)} {len(horiz)} 1 {units} " + \
        " ".join(fmt(d) for d in dims) + "\n"
    text += f"{fmt(ballast)} {fmt(third)} {fmt(watts)}\n"
    text += rows(vert, sep=sep) + "\n" + rows(horiz, sep=sep) + "\n"
    for column in table:
        text += rows(column, sep=sep) + "\n"
    with open(name, "w", newline="\n") as f:
        f.write(text)


H2002 = "IESNA:LM-63-2002\n[TEST] closed form, radiosity test data\n[MANUFAC] radiosity project\n"
H2019 = ("IES:LM-63-2019\n[TEST] closed form\n[TESTLAB] radiosity project\n"
         "[ISSUEDATE] 2026-12-03\n[MANUFAC] radiosity project\n")
H1995 = "IESNA:LM-63-1995\n[TEST] closed form\n[MANUFAC] radiosity project\n"

# Isotropic 100 cd over the sphere, written as 50 cd with a candela multiplier of 2.
vert = [0, 45, 90, 135, 180]
write("isotropic_lm63_2002.ies", H2002, 1, 4 * math.pi * 100, 2.0, vert, [0],
      [[50.0] * len(vert)])

# I0 cos(theta), I0 = 1000 cd, lower hemisphere, 1 degree steps: pi * 1000 lm.
vert = list(range(0, 91))
write("cosine_lm63_1995.ies", H1995, 1, math.pi * 1000, 1.0, vert, [0],
      [[1000 * math.cos(math.radians(t)) for t in vert]])

# Quadrant symmetric: 1000 cos(theta) (1 + 0.5 cos 2 phi), 5 degree by 15 degree steps.
vert = list(range(0, 91, 5))
def quad(phi):
    return [1000 * math.cos(math.radians(t)) * (1 + 0.5 * math.cos(2 * math.radians(phi)))
            for t in vert]
quarter = {phi: quad(phi) for phi in range(0, 91, 15)}
def fold_quadrant(phi):
    p = phi % 360
    if p > 180: p = 360 - p
    if p > 90: p = 180 - p
    return quarter[p]
full = list(range(0, 361, 15))
write("quadrant_full_lm63_2019.ies", H2019, 1, math.pi * 1000, 1.0, vert, full,
      [fold_quadrant(p) for p in full], third=1.00001)
write("quadrant_half_lm63_2019.ies", H2019, 1, math.pi * 1000, 1.0, vert, list(range(0, 181, 15)),
      [fold_quadrant(p) for p in range(0, 181, 15)], third=1.00001)
write("quadrant_quarter_lm63_2019.ies", H2019, 1, math.pi * 1000, 1.0, vert,
      list(range(0, 91, 15)), [fold_quadrant(p) for p in range(0, 91, 15)], third=1.00001)
# The full turn without its 360 column: the last (345) joins 0 again.
write("quadrant_open_lm63_2019.ies", H2019, 1, math.pi * 1000, 1.0, vert,
      list(range(0, 346, 15)), [fold_quadrant(p) for p in range(0, 346, 15)], third=1.00001)

# Bilateral about the 0-180 plane: 1000 cos(theta) (1 + 0.3 cos phi).
half = {phi: [1000 * math.cos(math.radians(t)) * (1 + 0.3 * math.cos(math.radians(phi)))
              for t in vert] for phi in range(0, 181, 15)}
fold0 = lambda p: half[p if p <= 180 else 360 - p]
write("bilateral0_full_lm63_2002.ies", H2002, 1, math.pi * 1000, 1.0, vert, full,
      [fold0(p) for p in full])
write("bilateral0_half_lm63_2002.ies", H2002, 1, math.pi * 1000, 1.0, vert,
      list(range(0, 181, 15)), [fold0(p) for p in range(0, 181, 15)])

# Bilateral about the 90-270 plane: 1000 cos(theta) (1 + 0.3 sin phi); commas between numbers.
half90 = {phi: [1000 * math.cos(math.radians(t)) * (1 + 0.3 * math.sin(math.radians(phi)))
                for t in vert] for phi in range(90, 271, 15)}
def fold90(p):
    if p < 90: p = 180 - p
    elif p > 270: p = 540 - p
    return half90[p]
write("bilateral90_full_lm63_2002.ies", H2002, 1, math.pi * 1000, 1.0, vert, full,
      [fold90(p) for p in full], sep=", ")
write("bilateral90_half_lm63_2002.ies", H2002, 1, math.pi * 1000, 1.0, vert,
      list(range(90, 271, 15)), [fold90(p) for p in range(90, 271, 15)], sep=", ")

# IESNA91 with TILT=INCLUDE: two lamps of 1000 lm, a uniform lower hemisphere of
# 2000 / (2 pi) cd, written with ballast factor 0.5 and ballast-lamp factor 2 (net 1).
vert = [0, 30, 60, 90]
write("tilt_include_iesna91.ies", "IESNA91\n[TEST] closed form\n", 2, 1000, 1.0, vert, [0],
      [[2000 / (2 * math.pi)] * len(vert)], ballast=0.5, third=2.0,
      tilt="TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9 0.8")

# LM-63-1986: no version line, free text, dimensions in feet, absolute photometry (-1).
vert = [0, 90, 180]
write("absolute_lm63_1986.ies", "radiosity test luminaire\nclosed form: isotropic 10 cd", 1, -1,
      1.0, vert, [0], [[10.0] * 3], units=1, dims=(1, 2, 0.5))
