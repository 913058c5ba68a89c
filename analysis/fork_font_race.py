"""Two drawers forked from a warm process, drawing the gain labels at once: do they read fonts right?

The region command's helper process warms up its plotting code (it parses the gain labels
with the Agg renderers' shared mathtext parser, :func:`stringstab.plots.share_mathtext_parser`)
and then forks two drawers.  A parse holds the fonts it was made with, and Agg loads their
glyphs again when it draws (``FT2Font._render_glyph`` → ``FT_Load_Glyph``), reading the font
file with ``seek`` then ``read`` on a file whose offset a fork shares with the parent and
every sibling.  Two drawers drawing parses made before the fork race on that offset: FreeType
errors ("invalid outline", "too many hints": the command fails) or a glyph drawn from the
wrong bytes (a figure silently different).

This script does what the command does, many times: a process parses the labels (by drawing
one figure), forks two children that each save ``--figures`` small figures with the three
gain labels, and counts per child the FreeType errors and the PNGs whose bytes differ from the
parent's (drawn before the fork, single process).  Run it on this checkout and on a base::

    python analysis/fork_font_race.py                                   # this checkout
    PYTHONPATH=/tmp/base python analysis/fork_font_race.py             # git archive BASE stringstab | tar -x -C /tmp/base

Measured (issue 31, fifth pass; each run 2 × 150 figures, load 1-4): the code of main at
8043ba3 gave 8, 3, 1 and 8 FreeType errors in four runs and 4 PNGs of other bytes in the 1,200
figures; with a parser of its own in each forked process, 0 errors and 0 other bytes in 1,500.  It forks from a single-threaded
process only (:func:`stringstab.parallel.check_single_threaded`).  Prints its counts; asserts
nothing.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from stringstab.parallel import check_single_threaded
from stringstab.plots import GAIN_LABELS, share_mathtext_parser


def _png_digest() -> str:
    fig = plt.figure(figsize=(3, 3))
    ax = fig.add_subplot()
    ax.set_xlabel(GAIN_LABELS["k_x"])
    ax.set_ylabel(GAIN_LABELS["k_v"])
    ax.set_title(GAIN_LABELS["k_a"])
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=150)
    plt.close(fig)
    return hashlib.sha1(buf.getvalue()).hexdigest()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--figures", type=int, default=150, help="figures per child (default 150)")
    a = ap.parse_args()
    share_mathtext_parser()
    reference = _png_digest()  # parses the labels here, before the fork
    children = []
    for child in range(2):
        check_single_threaded("a drawer")
        pid = os.fork()
        if pid == 0:
            errors = other = 0
            for _ in range(a.figures):
                try:
                    other += _png_digest() != reference
                except RuntimeError:  # FreeType's, from FT_Load_Glyph
                    errors += 1
            print(f"child {child}: {errors} FreeType errors, {other} PNGs of other bytes, "
                  f"of {a.figures} figures", flush=True)
            os._exit(0)
        children.append(pid)
    for pid in children:
        os.waitpid(pid, 0)


if __name__ == "__main__":
    main()
