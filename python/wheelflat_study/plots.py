"""The study's plots (matplotlib, PNG and PDF), as its `[[plot]]` entries ask:

* ``kind = "lines"``: `y` against `x`, one curve per value of `by`;
* ``kind = "heatmap"``: `z` over two swept variables `x` and `y`;
* ``kind = "phase"``: a heat map whose `x` is a phase angle (shown in degrees).
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
    z_label = p.get("label", p.get("y") if kind == "lines" else p.get("z"))
    if kind == "lines":
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
