"""The study's plots (matplotlib, PNG and PDF), as its `[[plot]]` entries ask:

* ``kind = "lines"``: `y` against `x`, one curve per value of `by`;
* ``kind = "heatmap"``: `z` over two swept variables `x` and `y`;
* ``kind = "phase"``: a heat map whose `x` is a phase angle (shown in degrees);
* ``kind = "distribution"``: the result `y` over each case group of the study's
  ``[summary]`` (the cases that differ only in its `over`, a track's seeds, say), a box
  plot per group (by the value of `by`, or by every swept variable outside `over`)
  with each case's value, the mean and the summary's percentile marked.
"""

import os


def _scaled(study, name, values):
    unit, f = study.display.get(name, (None, 1.0))
    label = f"{name} ({unit})" if unit else name
    return [v * f for v in values], label


def make_plots(study, table, out_dir, log=print):
    """Draws the study's plots; a plot that cannot be drawn (a column the results do
    not have, no successful case) is reported through `log` and skipped."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = table[table["status"] == "ok"] if "status" in table else table
    written = []
    for i, p in enumerate(study.plots):
        missing = [p[k] for k in ("x", "y", "z", "by") if k in p and p[k] not in ok.columns]
        if missing or ok.empty:
            why = f"no column {missing}" if missing else "no successful case"
            log(f"plot {i + 1} ({p.get('name', p.get('kind', 'lines'))}) skipped: {why}; "
                f"columns: {', '.join(map(str, table.columns))}")
            continue
        try:
            written += _plot(study, ok, out_dir, i, p, plt)
        except Exception as e:  # the tables are written; a plot never stops a study
            log(f"plot {i + 1} skipped: {type(e).__name__}: {e}")
            plt.close("all")
    return written


def _plot(study, ok, out_dir, i, p, plt):
    import numpy as np
    written = []
    kind = p.get("kind", "lines")
    name = p.get("name", f"{study.name}_{i + 1}_{kind}")
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    z_scale = float(p.get("scale", 1.0))
    z_label = p.get("label", p.get("y") if kind in ("lines", "distribution") else p.get("z"))
    if kind == "distribution":
        _distribution(study, ok, ax, p, z_scale, z_label)
    elif kind == "lines":
        groups = [(None, ok)] if "by" not in p else list(ok.groupby(p["by"], sort=True))
        for key, g in groups:
            g = g.sort_values(p["x"])
            xs, xl = _scaled(study, p["x"], g[p["x"]].tolist())
            label = None
            if key is not None:
                kv, _ = _scaled(study, p["by"], [key])
                unit = study.display.get(p["by"], ("",))[0]
                label = f"{p['by']} = {kv[0]:g} {unit}".strip()
            ax.plot(xs, g[p["y"]] * z_scale, "o-", ms=3, label=label)
        ax.set_xlabel(xl)
        ax.set_ylabel(z_label)
        if "by" in p:
            ax.legend(fontsize=8)
    else:
        xv = sorted(ok[p["x"]].unique())
        yv = sorted(ok[p["y"]].unique())
        grid = np.full((len(yv), len(xv)), np.nan)
        for _, r in ok.iterrows():
            grid[yv.index(r[p["y"]]), xv.index(r[p["x"]])] = r[p["z"]] * z_scale
        xs, xl = _scaled(study, p["x"], xv)
        ys, yl = _scaled(study, p["y"], yv)
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), grid, shading="flat", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=z_label)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
    ax.set_title(p.get("title", study.name))
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    for ext in ("png", "pdf"):
        path = os.path.join(out_dir, f"{name}.{ext}")
        fig.savefig(path, dpi=120)
        written.append(path)
    plt.close(fig)
    return written


def _edges(v):
    """Cell edges around sorted centres `v`."""
    if len(v) == 1:
        return [v[0] - 0.5, v[0] + 0.5]
    mids = [(a + b) / 2 for a, b in zip(v, v[1:])]
    return [v[0] - (mids[0] - v[0])] + mids + [v[-1] + (v[-1] - mids[-1])]


def _distribution(study, ok, ax, p, scale, label):
    """A distribution plot on `ax`: a box (quartiles, whiskers at 1.5 times the
    interquartile range) per case group of the summary, each case's value beside it,
    the mean (a diamond) and the summary's percentile (a bar) marked, as summary.py
    computes them."""
    import numpy as np
    from .run import percentile_words
    from .summary import group_names, groups, statistics
    q = study.summary.percentile
    names = group_names(study)
    boxes = []
    for key, g in groups(study, ok):
        values = g[p["y"]].to_numpy(dtype=float) * scale
        values = values[np.isfinite(values)]
        if "by" in p:
            text = study.shown(p["by"], key[p["by"]])
        else:
            text = "\n".join(f"{n} = {_with_unit(study, n, key[n])}" for n in names) or "all cases"
        boxes.append((text, values))
    boxes = [(t, v) for t, v in boxes if len(v)]
    if not boxes:
        raise ValueError(f"no case with a value of {p['y']}")
    positions = np.arange(1, len(boxes) + 1)
    ax.boxplot([v for _, v in boxes], positions=positions, widths=0.5, showfliers=False,
               medianprops={"color": "0.3"})
    rng = np.random.default_rng(0)
    for x, (_, v) in zip(positions, boxes):
        ax.plot(x + rng.uniform(-0.12, 0.12, len(v)) + 0.33, v, "o", ms=2.5, color="0.45", alpha=0.6,
                label="a case" if x == 1 else None)
        st = statistics(v, q)
        ax.plot([x], [st["mean"]], "D", ms=6, color="C3", label="mean" if x == 1 else None)
        ax.plot([x], [st["percentile"]], "_", ms=22, mew=2.5, color="C0",
                label=f"{percentile_words(q)[4:]} (linear)" if x == 1 else None)
    ax.set_xticks(positions)
    ax.set_xticklabels([t for t, _ in boxes], fontsize=8)
    over = ", ".join(study.summary.over)
    if "by" in p:
        unit = study.display.get(p["by"], (None,))[0]
        ax.set_xlabel(f"{p['by']} ({unit})" if unit and p["by"] not in study.items else p["by"])
    else:
        ax.set_xlabel("case group" if names else "")
    ax.set_ylabel(label)
    ax.legend(fontsize=8, title=f"over {over}", title_fontsize=8)


def _with_unit(study, name, v):
    """A group's value as a label shows it: ``60 km/h``, an enumeration's item."""
    unit = study.display.get(name, (None,))[0]
    shown = study.shown(name, v)
    return f"{shown} {unit}" if unit and name not in study.items else shown
