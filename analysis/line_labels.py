"""Names of vertical marker lines (t₀, t_c, contact, collision #3) that stay readable: each
label at the top of its axes beside its line, moved down a row while it would overlap another
label or the legend, and turned to the line's left side where it would leave the axes.

Placed from the drawn sizes of the texts, so call :func:`place` after the figure's final
layout (``tight_layout``): the figure functions collect their marks, then place them."""

from __future__ import annotations

from matplotlib.text import Annotation

PAD = 2.0  # points between a line and its label
ROW = 8.5  # points from one row of labels to the next
MAX_ROWS = 8
# the marks (event lines, shaded phases) of one kind that one axes draws: a log's event count
# does not set a figure's cost (each mark is an artist; 10,000 took ~70 s and 460 MB)
MAX_MARKS = 40
MORE = f"only the first {MAX_MARKS} marks of a kind drawn"


def first(items) -> tuple[list, bool]:
    """The first :data:`MAX_MARKS` of ``items`` (a log's events to mark), and whether there
    were more."""
    items = list(items)
    return items[:MAX_MARKS], len(items) > MAX_MARKS


def _extent(fig, ann: Annotation):
    return ann.get_window_extent(fig.canvas.get_renderer()).expanded(1.02, 1.0)


def _overlaps(box, boxes) -> bool:
    return any(box.overlaps(b) for b in boxes)


def place(ax, marks, fontsize: float = 7, color: str = "0.35") -> list[Annotation]:
    """Label the lines ``marks`` ((x, text), x in data units) of ``ax``: those inside its x
    range, in x order, each in the first row from the top where it overlaps nothing placed."""
    fig = ax.figure
    lo, hi = sorted(ax.get_xlim())
    inside = ax.get_window_extent()
    taken = []
    legend = ax.get_legend()
    if legend is not None:
        taken.append(legend.get_window_extent(fig.canvas.get_renderer()))
    out = []
    for x, text in sorted((m for m in marks if m[0] is not None), key=lambda m: m[0]):
        if not lo <= x <= hi:
            continue
        ann = ax.annotate(
            text,
            (x, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(PAD, -ROW),
            textcoords="offset points",
            fontsize=fontsize,
            color=color,
            va="baseline",
            annotation_clip=False,
            bbox=dict(boxstyle="square,pad=0.1", fc="white", ec="none", alpha=0.7),
        )
        for row in range(MAX_ROWS):
            y = -ROW * (row + 1)
            ann.set_horizontalalignment("left")
            ann.xyann = (PAD, y)
            box = _extent(fig, ann)
            if box.x1 > inside.x1:  # would leave the axes on the right: the line's left side
                ann.set_horizontalalignment("right")
                ann.xyann = (-PAD, y)
                box = _extent(fig, ann)
            if not _overlaps(box, taken):
                break
        taken.append(box)
        out.append(ann)
    return out
