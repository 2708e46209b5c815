"""Centerline CSV texts for the tests of a patient's centerline (mm; the format of
``colonsim.insertion.anatomy.centerline_file``)."""

import numpy as np

PLAIN = "x_mm,y_mm,z_mm,label\n"


def csv_text(rows, first_label="mobile"):
    """A file of ``rows`` (x, y, z) in mm, labelled ``first_label`` from the first point on."""
    return PLAIN + "".join(f"{x:.3f},{y:.3f},{z:.3f},{first_label if i == 0 else ''}\n"
                           for i, (x, y, z) in enumerate(rows))


def hairpin():
    """6 cm straight, then a half turn of radius 12 mm: tighter than a 36 mm colon can follow."""
    theta = np.linspace(0.0, np.pi, 12)
    return csv_text([(0, y, 0) for y in range(0, 60, 10)]
                    + [(-12 + 12 * np.cos(a), 60 + 12 * np.sin(a), 0) for a in theta[1:]])


def loop():
    """A loop of radius 3 cm turning 342 deg: its ends pass 2 cm apart."""
    theta = np.linspace(0.0, 1.9 * np.pi, 40)
    return csv_text([(30 * np.sin(a), 30 - 30 * np.cos(a), 0.0) for a in theta])
