"""The script that regenerates the paper's Figs. 2-6 runs and writes every figure."""

import subprocess
import sys
from pathlib import Path

import matplotlib.image

SCRIPT = Path(__file__).resolve().parents[1] / "examples" / "paper_figures.py"
FIGURES = (
    "fig2_cor_and_limit_curve.png",
    "fig3_normalised_limit_curves.png",
    "fig4_rectangle_limit_surface.png",
    "fig5_rectangle_sections.png",
    "fig6_point_supports.png",
)


def test_paper_figures_script_writes_figs_2_to_6(tmp_path):
    result = subprocess.run(
        [sys.executable, str(SCRIPT), "--out", str(tmp_path)], capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    for name in FIGURES:
        image = matplotlib.image.imread(tmp_path / name)
        # A drawn figure, not a blank canvas: many distinct colours.
        colours = {tuple(pixel) for pixel in image.reshape(-1, image.shape[-1])[::97]}
        assert len(colours) > 20, name
