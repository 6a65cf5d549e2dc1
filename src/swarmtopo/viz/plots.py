"""Matplotlib figures.  Every function takes ``ax=None`` and returns the Axes; none
calls ``plt.show()`` or changes global style.  matplotlib is imported here only."""

from __future__ import annotations

import numpy as np

from ..topology.persistence import Diagram

_DIM_COLORS = {0: "tab:blue", 1: "tab:red", 2: "tab:green"}


def _axes(ax, projection=None):
    if ax is not None:
        return ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5, 5))
    return fig.add_subplot(projection=projection)


def plot_diagram(diagram: Diagram, ax=None, *, thresholds: dict[int, float] | None = None, title=None):
    """Persistence diagram: births against deaths per dimension, infinite deaths on a
    dashed line at the top; optional significance threshold per dimension drawn as a
    line parallel to the diagonal (death = birth + threshold)."""
    ax = _axes(ax)
    finite = [diagram[n][np.isfinite(diagram[n][:, 1])] for n in range(diagram.maxdim + 1)]
    values = np.concatenate([f.ravel() for f in finite] + [diagram[0][:, 0]])
    top = float(values.max()) if values.size else 1.0
    top = top * 1.1 if top > 0 else 1.0
    for n in range(diagram.maxdim + 1):
        pts = diagram[n]
        inf = ~np.isfinite(pts[:, 1])
        color = _DIM_COLORS.get(n, "k")
        ax.scatter(pts[~inf, 0], pts[~inf, 1], s=12, color=color, label=f"H{n} ({len(pts)})", alpha=0.8)
        if inf.any():
            ax.scatter(pts[inf, 0], np.full(inf.sum(), top), s=30, marker="^", color=color)
        if thresholds and n in thresholds:
            tau = thresholds[n]
            ax.plot([0, top], [tau, top + tau], ls=":", color=color, lw=1, label=f"H{n} threshold")
    ax.plot([0, top], [0, top], color="0.5", lw=1)
    ax.axhline(top, ls="--", color="0.7", lw=0.8)
    ax.set_xlim(-0.02 * top, top * 1.02)
    ax.set_ylim(-0.02 * top, top * 1.05)
    ax.set_xlabel("birth (s)")
    ax.set_ylabel("death (s)")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title or "persistence diagram")
    return ax


def plot_barcode(diagram: Diagram, ax=None, *, dims=(0, 1), thresholds: dict[int, float] | None = None,
                 max_bars: int = 60, title=None):
    """Barcode: the ``max_bars`` longest bars of each dimension, longest on top;
    infinite bars run to the right edge with an arrow.  With ``thresholds``, bars
    longer than their dimension's threshold are drawn solid, the others faded."""
    ax = _axes(ax)
    dims = [n for n in dims if n <= diagram.maxdim]
    finite_deaths = np.concatenate([diagram[n][np.isfinite(diagram[n][:, 1]), 1] for n in dims] + [[1.0]])
    right = float(finite_deaths.max()) * 1.1
    y = 0
    for n in dims:
        bars = diagram[n][:max_bars]
        color = _DIM_COLORS.get(n, "k")
        limit = thresholds.get(n) if thresholds else None
        for birth, death in bars[::-1]:
            end = death if np.isfinite(death) else right
            faded = limit is not None and death - birth <= limit
            ax.plot([birth, end], [y, y], color=color, lw=2, solid_capstyle="butt", alpha=0.3 if faded else 1.0)
            if not np.isfinite(death):
                ax.annotate("", xy=(right, y), xytext=(right * 0.97, y), arrowprops=dict(arrowstyle="->", color=color))
            y += 1
        label = f"H{n}" + (f" (solid: longer than {limit:.3g})" if limit is not None else "")
        ax.text(right, y - 0.5, label, ha="right", va="top", color=color, fontsize=8)
        y += 2
    ax.set_yticks([])
    ax.set_xlabel("filtration scale (s)")
    ax.set_title(title or "barcode")
    return ax


def plot_point_cloud(coords: np.ndarray, color, ax=None, *, cmap="viridis", label=None, title=None):
    """MDS encounter point cloud (2-D or 3-D coords), coloured by ``color``: an array
    of values (colour map, with colour bar) or an (n, 3) RGB array."""
    dim = coords.shape[1]
    ax = _axes(ax, projection="3d" if dim == 3 else None)
    color = np.asarray(color)
    rgb = color.ndim == 2
    kwargs = dict(c=color, s=10, depthshade=False) if dim == 3 else dict(c=color, s=10)
    if not rgb:
        kwargs["cmap"] = cmap
    sc = ax.scatter(*coords.T, **kwargs)
    if not rgb and label:
        ax.figure.colorbar(sc, ax=ax, shrink=0.6, label=label)
    ax.set_title(title or "encounter point cloud (MDS)")
    return ax


def plot_arena(arena, ax=None, *, points: np.ndarray | None = None, color=None, title=None):
    """The arena (free space grey, walls black) with optional points at true positions."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as DrawnPath

    ax = _axes(ax)
    for region in arena.regions:
        for ring in region.interiors:  # obstacles under the free space, so a room inside a hole shows
            ax.fill(*ring.xy, color="0.45", zorder=0)
        rings = [region.exterior, *region.interiors]  # shell counter-clockwise, holes clockwise: holes cut out
        free = DrawnPath.make_compound_path(*(DrawnPath(np.asarray(r.coords), closed=True) for r in rings))
        ax.add_patch(PathPatch(free, facecolor="0.93", edgecolor="none", zorder=0.5))
        for ring in rings:
            ax.plot(*ring.xy, color="k", lw=1.5)
    if points is not None and len(points):
        ax.scatter(points[:, 0], points[:, 1], c=color, s=8, zorder=2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title or "arena (ground truth)")
    return ax


def position_colors(xy: np.ndarray, bounds) -> np.ndarray:
    """RGB colours encoding a true position: red grows with x, blue with y."""
    xmin, ymin, xmax, ymax = bounds
    u = np.clip((xy[:, 0] - xmin) / max(xmax - xmin, 1e-12), 0, 1)
    v = np.clip((xy[:, 1] - ymin) / max(ymax - ymin, 1e-12), 0, 1)
    return np.column_stack([0.15 + 0.8 * u, 0.35 + 0.3 * (1 - np.abs(u - v)), 0.15 + 0.8 * v])


def new_figure(width: float, height: float):
    """A Figure not attached to pyplot's global state (safe in threads and workers)."""
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


# -- figures of the paper's experiments (swarmtopo.experiments.reproduce) -------------------
def cyclic_colors(angle: np.ndarray, cmap: str = "twilight") -> np.ndarray:
    """RGB colours of angles (radians) on a cyclic colour map: -pi and pi get one colour."""
    from matplotlib import colormaps

    fraction = np.mod(np.asarray(angle, dtype=float), 2 * np.pi) / (2 * np.pi)
    return colormaps[cmap](fraction)[:, :3]


def plot_bar_separation(longest, second, ax=None, *, groups=None, title=None):
    """Longest against second-longest H1 bar, one point per run.

    A run with one clear hole sits far above the diagonal (drawn, with the line
    longest = 2 x second dashed); noise alone sits near it.  ``groups`` (one label per
    run) colours the runs by condition, with a legend.
    """
    ax = _axes(ax)
    longest, second = np.asarray(longest, dtype=float), np.asarray(second, dtype=float)
    labels = np.asarray(groups if groups is not None else [""] * len(longest), dtype=object)
    for i, label in enumerate(dict.fromkeys(labels.tolist())):
        pick = labels == label
        ax.scatter(second[pick], longest[pick], s=22, alpha=0.8, color=f"C{i}", label=label or None)
    finite = np.concatenate([longest[np.isfinite(longest)], second[np.isfinite(second)], [1.0]])
    top = float(finite.max()) * 1.1
    ax.plot([0, top], [0, top], color="0.5", lw=1, label="longest = second")
    ax.plot([0, top / 2], [0, top], color="0.5", lw=1, ls="--", label="longest = 2 x second")
    ax.set_xlim(0, top)
    ax.set_ylim(0, top)
    ax.set_xlabel("second-longest H1 bar (s)")
    ax.set_ylabel("longest H1 bar (s)")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title or "H1 bar separation per run")
    return ax


def plot_distributions(samples, ax=None, *, ylabel: str = "", log_scale: bool = False, title=None):
    """Box plot of one sample per label (``samples``: mapping label -> values; box:
    quartiles, whiskers: minimum to maximum), with the values themselves overlaid
    (evenly spread sideways in order, no randomness) and each mean marked by a diamond.
    Infinite values are left out."""
    ax = _axes(ax)
    labels = list(samples)
    values = [np.asarray(samples[k], dtype=float) for k in labels]
    values = [v[np.isfinite(v)] for v in values]
    ax.boxplot(values, tick_labels=labels, whis=(0, 100), showfliers=False, widths=0.5)
    for i, v in enumerate(values, start=1):
        offsets = np.linspace(-0.18, 0.18, len(v)) if len(v) > 1 else np.zeros(len(v))
        ax.scatter(i + offsets[np.argsort(np.argsort(v))], v, s=8, alpha=0.45, color=f"C{i - 1}")
        if len(v):
            ax.scatter([i], [v.mean()], marker="D", s=40, color="k", zorder=3,
                       label="mean" if i == 1 else None)
    if log_scale:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    if any(len(v) for v in values):
        ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title or "")
    return ax


def plot_ratio_density(diagrams, truth, theta, ax=None, *, dim: int = 1, title=None):
    """Density of the scaled lengths l / (l_q + Delta) of dgm_dim over many maps, the
    true beta longest bars of each map ("holes") apart from the rest, with tau drawn
    (the paper's Fig. "clust" (c))."""
    from ..readers.paper import bar_lengths, quantile_scale

    ax = _axes(ax)
    holes, rest = [], []
    for dgm, beta in zip(diagrams, truth):
        lengths = bar_lengths(dgm, dim)
        lengths = lengths[np.isfinite(lengths)]
        scale = quantile_scale(lengths, theta.q, theta.delta)
        if scale <= 0 or not len(lengths):
            continue
        ratios = lengths / scale  # decreasing, like the lengths
        holes.append(ratios[:beta])
        rest.append(ratios[beta:])
    holes, rest = np.concatenate(holes or [[]]), np.concatenate(rest or [[]])
    both = np.concatenate([holes, rest])
    both = both[both > 0]
    if len(both):
        bins = np.geomspace(both.min(), both.max(), 60)
        ax.hist(rest[rest > 0], bins=bins, density=True, alpha=0.6, color="tab:gray", label="other bars")
        ax.hist(holes[holes > 0], bins=bins, density=True, alpha=0.6, color="tab:red",
                label="the beta longest bars")
    ax.axvline(theta.tau, color="k", ls="--", lw=1, label=f"tau = {theta.tau:.2g}")
    ax.set_xscale("log")
    ax.set_xlabel(f"l / (l_q + Delta),  q = {theta.q:.2g}, Delta = {theta.delta:.2g} s")
    ax.set_ylabel("density")
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def plot_scores_by(values, series: dict, ax=None, *, xlabel: str, ylabel: str, title=None):
    """One line per entry of ``series`` (name -> score per value of ``values``)."""
    ax = _axes(ax)
    for name, scores in series.items():
        ax.plot(values, scores, marker="o", label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xticks(list(values))
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def plot_cycles(arena, loops, ax=None, *, points: np.ndarray | None = None, color=None, correct=None, title=None):
    """Representative cycles drawn at the true positions of their events on the arena.

    ``loops`` is a list of (k, 2) arrays of true positions in loop order (closed
    here); ``correct`` optionally flags each loop (green if it encircles exactly one
    obstacle, orange otherwise); without it loops take the tab10 colours.
    ``points`` / ``color``: other events drawn under the loops (as in :func:`plot_arena`).
    """
    ax = plot_arena(arena, ax, points=points, color=color, title=title or "representative cycles at true positions")
    for k, loop in enumerate(loops):
        loop = np.asarray(loop, dtype=float)
        closed = np.vstack([loop, loop[:1]])
        color = f"C{k % 10}" if correct is None else ("tab:green" if correct[k] else "tab:orange")
        ax.plot(closed[:, 0], closed[:, 1], "-", color=color, lw=2, zorder=3)
        ax.scatter(loop[:, 0], loop[:, 1], color=color, s=18, edgecolor="k", lw=0.5, zorder=4)
    return ax
