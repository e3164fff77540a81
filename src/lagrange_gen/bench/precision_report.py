"""Figures and markdown of the precision suite: work-precision panels (failed runs as crosses on
a 'failed' line), per-model summary tables (interpolated time to a final-state error) and the
headline (best of ours against each peer at final error 1e-8)."""

from __future__ import annotations

from . import common
from ..analysis import runs
from .common import TARGET, by_method, time_at


def _panel(ax, points, key, label):
    """log error (key) vs log wall time, one curve per method; failed runs as crosses on a
    'failed' line above the largest finite error."""
    finite = [getattr(pt, key) for pt in points if not pt.failed and getattr(pt, key) > 0]
    if not finite:
        ax.set_visible(False)
        return
    ceiling = 10 * max(max(finite), 1e-16)
    floor = min(finite)
    for i, (method, pts) in enumerate(by_method(points).items()):
        ours = pts[0].kind == "ours"
        good = [pt for pt in pts if not pt.failed and getattr(pt, key) > 0]
        style = dict(color=f"C{i % 10}", marker="o" if ours else "s", ms=4,
                     ls="-" if ours else "--")
        if good:
            ax.loglog([pt.wall for pt in good], [getattr(pt, key) for pt in good], label=method,
                      **style)
        bad = [pt for pt in pts if pt.failed]
        if bad:
            ax.loglog([max(pt.wall, 1e-6) for pt in bad], [ceiling] * len(bad), ls="none",
                      marker="x", ms=7, color=style["color"],
                      label=None if good else f"{method} (all failed)")
    ax.axhline(ceiling, color="0.6", lw=0.5)
    ax.text(0.01, ceiling, " failed", transform=ax.get_yaxis_transform(), va="bottom",
            fontsize=7, color="0.4")
    ax.set_ylim(floor / 3, ceiling * 5)
    ax.set_xlabel("wall time [s] (integration only, min of repeats)")
    ax.set_ylabel(label)
    ax.grid(True, which="major", alpha=0.3)


def figure(result, path):
    """PNG: final-state error and max |E - E0| (max |Phi| for constrained models) vs time."""
    fig, (a, b) = common.new_figure(1, 2, figsize=(13, 5.2))
    _panel(a, result["points"], "final", "final-state error (max norm)")
    if result["case"].constrained:
        _panel(b, result["points"], "phi", "max |Phi| over the samples")
    else:
        _panel(b, result["points"], "energy", "max |E - E0| over the samples")
    case = result["case"]
    fig.suptitle(f"{result['model']}: work-precision to T = {case.t_end:g} "
                 f"(h = {case.t_end / case.n0:g} / 2^k; peers over rtol)")
    handles, labels = a.get_legend_handles_labels()
    if handles:
        b.legend(handles, labels, fontsize=7, loc="best")
    return common.save_figure(fig, path)


def _ms(x):
    return "-" if x is None else f"{x * 1e3:.3g} ms"


def summary_rows(result, targets=(1e-4, 1e-6, TARGET)):
    """Per method: kind, interpolated times at the targets, smallest final error, failures."""
    rows = []
    for method, pts in by_method(result["points"]).items():
        good = [pt.final for pt in pts if not pt.failed]
        rows.append([method, pts[0].kind, *(_ms(time_at(pts, t)) for t in targets),
                     runs.fmt(min(good)) if good else "-",
                     f"{sum(1 for pt in pts if pt.failed)} / {len(pts)}"])
    return rows


def headline(result, target=TARGET):
    """Best of ours at final error ``target`` against every peer: dict with 'best' (method,
    seconds) and 'peers' {name: seconds or None}."""
    times = {m: time_at(pts, target) for m, pts in by_method(result["points"]).items()}
    kinds = {pt.method: pt.kind for pt in result["points"]}
    ours = {m: t for m, t in times.items() if kinds[m] == "ours" and t is not None}
    best = min(ours.items(), key=lambda kv: kv[1]) if ours else (None, None)
    return {"best": best, "peers": {m: t for m, t in times.items() if kinds[m] == "peer"},
            "target": target}


def _full_table(points):
    rows = [[pt.method, f"{pt.param:.3g}", _ms(pt.wall), runs.fmt(pt.final),
             runs.fmt(pt.traj_max), runs.fmt(pt.energy), runs.fmt(pt.phi),
             runs.short_error(pt.failed) if pt.failed else "ok"] for pt in points]
    return runs.md_table(["method", "h or rtol", "wall", "final error", "max error",
                          "max abs(E - E0)", "max abs(Phi)", "status"], rows)


def case_markdown(result, figure_name):
    case, refr = result["case"], result["reference"]
    lines = [f"## {result['model']}", "",
             f"q0 = {tuple(round(x, 6) for x in case.q0)}, v0 = {tuple(case.v0)}, "
             f"T = {case.t_end:g}, h = {case.t_end / case.n0:g} / 2^k {case.note}; "
             f"errors at {case.samples + 1} sample times. Reference: DOP853 at rtol 1e-13; "
             f"second solver ({refr.second}) agrees to {refr.agreement:.1e}.", ""]
    if result["missing"]:
        lines += [f"Constrained steppers: **{result['missing']}** (only the peers ran).", ""]
    lines += runs.md_table(["method", "kind", "time to final error 1e-4", "1e-6", "1e-8",
                            "smallest final error", "failed runs"], summary_rows(result))
    lines += ["", f"![{result['model']}]({figure_name})", "", "<details><summary>every run"
              "</summary>", "", *_full_table(result["points"]), "", "</details>", ""]
    return lines


def headline_lines(result):
    """Markdown lines: the best of ours at final error 1e-8 against each peer, with ratios."""
    hl = headline(result)
    method, best = hl["best"]
    if best is None:
        return [f"No stepper reached final error {hl['target']:g} on {result['model']}."]
    rows = [[f"**{method}** (ours, best)", _ms(best), "1"]]
    for name, t in hl["peers"].items():
        rows.append([name, _ms(t), "-" if t is None else f"{t / best:.0f}x slower"])
    if not any(name.startswith("PyDy") for name in hl["peers"]):
        rows.append(["PyDy + DOP853", "pydy not installed", "-"])
    return [f"{result['model']} to T = {result['case'].t_end:g}, wall time to reach final-state "
            f"error {hl['target']:g} (interpolated on the work-precision curves below):", "",
            *runs.md_table(["method", "time", "ratio"], rows), ""]
