"""The figures of Experiment 1: the legend covers no curve, runs are whole numbers."""

from __future__ import annotations

from pathlib import Path

import pytest

from relrl.experiments.results import cgi_figure, plot


def _summary(points: int = 5) -> dict:
    """Four learners whose curves climb to the top of the plot, where a legend would sit."""
    out = {}
    for k, name in enumerate(["contingency", "qlearning", "etg", "tg"]):
        curve = [{"point": p, "learning_steps": 500 * p,
                  "cgi_mean": min(1.0, 0.2 + 0.25 * p + 0.02 * k), "cgi_std": 0.05,
                  "cgi_literal_mean": min(1.0, 0.1 + 0.25 * p), "cgi_literal_std": 0.05,
                  "n_runs": 5} for p in range(points)]
        out[name] = {"curve": curve, "eye_contacts": {"cumulative_mean": [0.5 * i for i in
                                                                          range(20)],
                                                     "mean": 10.0, "std": 1.0}}
    return out


@pytest.mark.parametrize("points", [2, 5, 21])
@pytest.mark.slow
def test_fig5_legend_covers_no_curve_and_runs_are_whole(points: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = cgi_figure(plt, _summary(points))
    fig.canvas.draw()
    legend = ax.get_legend().get_window_extent()
    axes = ax.get_window_extent()
    assert not legend.overlaps(axes), (legend, axes)
    lo, hi = ax.get_xlim()
    shown = [x for x in ax.get_xticks() if lo <= x <= hi]
    assert shown and all(float(x).is_integer() for x in shown), shown
    assert "500 learning time units each" in ax.get_xlabel()
    plt.close(fig)


@pytest.mark.slow
def test_the_figures_are_written(tmp_path: Path) -> None:
    files = plot(tmp_path, _summary())
    assert [f.name for f in files] == ["fig5_cgi.png", "fig4_eye_contacts.png"]
    assert all(f.stat().st_size > 10_000 for f in files)


def test_loglog_slope_is_the_growth_exponent() -> None:
    """cost ∝ size^k: k from all the points, whatever the constant; None without two sizes
    or with a value that cannot be logged."""
    from relrl.experiments.results import loglog_slope

    assert loglog_slope([3, 6, 12], [5.0, 20.0, 80.0]) == pytest.approx(2.0)
    assert loglog_slope([3, 5, 10], [7.0, 7.0, 7.0]) == pytest.approx(0.0)
    assert loglog_slope([3, 4, 5], [3.0, 4.0, 5.0]) == pytest.approx(1.0)
    assert loglog_slope([3], [1.0]) is None
    assert loglog_slope([3, 6], [1.0, None]) is None
