"""Regenerate Figs. 2-6 of Howe & Cutkosky from fixplan's exact limit surfaces and models.

Run: ``python examples/paper_figures.py [--out DIR]`` (default ``examples/output/``). Writes
``fig2_cor_and_limit_curve.png`` ... ``fig6_point_supports.png``. Each figure's data are
computed first and drawn second; drawing uses matplotlib's object API with the Agg canvas, and
the PNG files carry no time stamp, so reruns give identical files.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Rectangle

from fixplan import LimitSurface, pressure
from fixplan.models import Cone, Ellipsoid, FacetedEllipsoid

RADIUS = 0.01  # [m]
MU = 0.5
NORMAL_FORCE = 10.0  # [N]


def _surface(field) -> LimitSurface:
    return LimitSurface(field, mu=MU, normal_force=NORMAL_FORCE)


def _normalised(ls: LimitSurface, loads: np.ndarray) -> np.ndarray:
    return loads / np.array([ls.max_force, ls.max_force, ls.max_moment])


def _surface_mesh(ls: LimitSurface, n_polar: int = 41, n_azimuth: int = 72) -> np.ndarray:
    """Normalised loads ``(n_polar, n_azimuth + 1, 3)`` on the surface, for ``plot_surface``."""
    polar = np.linspace(0.0, np.pi, n_polar)
    azimuth = np.linspace(0.0, 2.0 * np.pi, n_azimuth + 1)
    pp, aa = np.meshgrid(polar, azimuth, indexing="ij")
    directions = np.stack(
        [np.sin(pp) * np.cos(aa), np.sin(pp) * np.sin(aa), np.cos(pp)], axis=-1
    ).reshape(-1, 3)
    units = np.array([ls.max_force, ls.max_force, ls.max_moment])
    loads = directions * units * ls.safety_factor(directions * units)[:, None]
    return _normalised(ls, loads).reshape(n_polar, n_azimuth + 1, 3)


def _save(fig: Figure, path: Path) -> None:
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=120, metadata={"Software": None})


# -- Fig. 2 ------------------------------------------------------------------------------------


def figure_2() -> Figure:
    """Uniform disk: centres of rotation on the x axis and their loads on the limit curve."""
    ls = _surface(pressure.disk(RADIUS))
    ratios = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0])
    cors = np.column_stack([ratios * RADIUS, np.zeros(len(ratios))])
    marked = np.abs(ls.load_at_cor(cors))
    curve = np.abs(ls.curve("fy-m", 181))
    curve = curve[(curve[:, 1] >= 0) & (curve[:, 2] >= 0)]

    fig = Figure(figsize=(10, 4.5))
    plane, plot = fig.subplots(1, 2)
    plane.add_patch(Circle((0.0, 0.0), RADIUS * 1e3, fill=False, color="0.3"))
    colours = [f"C{i}" for i in range(len(ratios))]
    plane.scatter(cors[:, 0] * 1e3, cors[:, 1] * 1e3, c=colours, zorder=3)
    for k, ((x, _), ratio) in enumerate(zip(cors, ratios, strict=True)):
        offset = (0, 8) if k % 2 == 0 else (0, -16)
        plane.annotate(
            f"{ratio:g}", (x * 1e3, 0.0), textcoords="offset points", xytext=offset, ha="center"
        )
    plane.set_xlim(-1.3 * RADIUS * 1e3, 4.5 * RADIUS * 1e3)
    plane.set_aspect("equal")
    plane.set_xlabel("x [mm]")
    plane.set_ylabel("y [mm]")
    plane.set_title("(a) centre of rotation at c/R on the x axis")
    plot.plot(curve[:, 1], curve[:, 2], color="0.3", label="limit curve")
    plot.scatter(marked[:, 1], marked[:, 2], c=colours, zorder=3)
    plot.scatter([ls.max_force], [0.0], c="k", marker="x", label="pure translation (c = ∞)")
    plot.set_xlabel("|f_y| [N]")
    plot.set_ylabel("|m| [N m]")
    plot.set_title("(b) force and moment on the limit curve")
    plot.legend(loc="upper right")
    fig.suptitle("Fig. 2: uniform circular contact, R = 10 mm, μN = 5 N")
    fig.tight_layout()
    return fig


# -- Fig. 3 ------------------------------------------------------------------------------------


def figure_3() -> Figure:
    """Normalised limit curves of three disks and the ellipse (and the cone's straight line)."""
    fields = {
        "Hertzian": pressure.disk(RADIUS, "hertz"),
        "uniform": pressure.disk(RADIUS),
        "annular, s = 0.9": pressure.disk(RADIUS, "annulus", inner_radius=0.9 * RADIUS),
    }
    curves = {}
    for name, field in fields.items():
        ls = _surface(field)
        curve = ls.curve("fy-m", 361, normalized=True)
        curves[name] = curve[(curve[:, 1] >= -1e-12) & (curve[:, 2] >= -1e-12)]
    angle = np.linspace(0.0, np.pi / 2, 91)

    fig = Figure(figsize=(5.5, 5.0))
    ax = fig.subplots()
    for name, curve in curves.items():
        ax.plot(curve[:, 1], curve[:, 2], label=name)
    ax.plot(np.cos(angle), np.sin(angle), "k--", label="ellipse")
    ax.plot([0.0, 1.0], [1.0, 0.0], ":", color="0.5", label="cone (straight line)")
    ax.set_xlim(0.0, 1.05)
    ax.set_ylim(0.0, 1.05)
    ax.set_aspect("equal")
    ax.set_xlabel("f / f_max")
    ax.set_ylabel("m / m_max")
    ax.set_title("Fig. 3: normalised limit curves")
    ax.legend(loc="lower left")
    fig.tight_layout()
    return fig


# -- Fig. 4 ------------------------------------------------------------------------------------


def figure_4() -> Figure:
    """Limit surface of a 10:1 uniform rectangle, normalised axes."""
    length, width = 10 * RADIUS, RADIUS
    mesh = _surface_mesh(_surface(pressure.rectangle(length, width)))

    fig = Figure(figsize=(6.5, 6.0))
    ax = fig.add_subplot(projection="3d")
    ax.plot_surface(
        mesh[..., 0], mesh[..., 1], mesh[..., 2], cmap="viridis", linewidth=0.2, edgecolor="k"
    )
    ax.set_xlabel("f_x / f_max")
    ax.set_ylabel("f_y / f_max")
    ax.set_zlabel("m / m_max")
    ax.set_box_aspect((1, 1, 1))
    ax.set_title("Fig. 4: limit surface of a 10:1 rectangle")
    inset = fig.add_axes((0.03, 0.8, 0.22, 0.12))
    inset.add_patch(Rectangle((-length / 2, -width / 2), length, width, color="C0"))
    inset.set_xlim(-0.6 * length, 0.6 * length)
    inset.set_ylim(-0.6 * length / 5, 0.6 * length / 5)
    inset.set_aspect("equal")
    inset.set_xticks([])
    inset.set_yticks([])
    inset.set_title("contact", fontsize=8)
    return fig


# -- Fig. 5 ------------------------------------------------------------------------------------


def figure_5() -> Figure:
    """(f_x, m) and (f_y, m) sections of the 10:1 rectangle, the ellipse, and normals."""
    ls = _surface(pressure.rectangle(10 * RADIUS, RADIUS))
    ellipse = Ellipsoid.from_limit_surface(ls)
    cone = Cone.from_limit_surface(ls)
    distances = np.array([0.2, 0.5, 1.0, 2.0, 5.0]) * RADIUS
    sections = {}
    for plane, axis in (("fx-m", 0), ("fy-m", 1)):
        # Centres of rotation on the minor (y) axis give the (fx, m) section, on the major
        # (x) axis the (fy, m) section; ccw rotation about c is the twist (cy, -cx, 1).
        cors = np.zeros((len(distances), 2))
        cors[:, 1 - axis] = distances
        loads = ls.load_at_cor(cors)
        twists = ls.motion(loads)
        normals = twists * np.array([1.0, 1.0, ls.characteristic_length])
        sections[plane] = {
            "exact": ls.curve(plane, 361, normalized=True),
            "ellipse": ellipse.curve(plane, 361, normalized=True),
            "cone": cone.curve(plane, 361, normalized=True),
            "points": _normalised(ls, loads),
            "normals": normals,
            "axis": axis,
        }

    fig = Figure(figsize=(10, 4.8))
    for ax, data in zip(fig.subplots(1, 2), sections.values(), strict=True):
        i = data["axis"]
        ax.plot(data["exact"][:, i], data["exact"][:, 2], label="limit surface")
        ax.plot(data["ellipse"][:, i], data["ellipse"][:, 2], "k--", label="ellipse")
        ax.plot(data["cone"][:, i], data["cone"][:, 2], ":", color="0.5", label="cone")
        p, n = data["points"], data["normals"]
        n = n[:, [i, 2]] / np.linalg.norm(n[:, [i, 2]], axis=1, keepdims=True)
        ax.quiver(
            p[:, i],
            p[:, 2],
            n[:, 0],
            n[:, 1],
            angles="xy",
            scale_units="xy",
            scale=5,
            width=0.004,
            label="normal = sliding twist",
        )
        ax.set_aspect("equal")
        ax.set_xlim(-1.3, 1.3)
        ax.set_ylim(-1.1, 1.3)
        name = "f_x" if i == 0 else "f_y"
        ax.set_xlabel(f"{name} / f_max")
        ax.set_ylabel("m / m_max")
        ax.set_title(f"({name}, m) section")
        ax.legend(loc="lower left", fontsize=8)
    fig.suptitle("Fig. 5: sections of the 10:1 rectangle's limit surface, with normals")
    fig.tight_layout()
    return fig


# -- Fig. 6 ------------------------------------------------------------------------------------


def figure_6() -> Figure:
    """Three isolated support points and their faceted limit surface."""
    radius = 5 * RADIUS
    angles = np.pi / 2 + 2 * np.pi * np.arange(3) / 3
    xy = radius * np.column_stack([np.cos(angles), np.sin(angles)])
    ls = _surface(pressure.points(xy))
    mesh = _surface_mesh(ls, 61, 96)
    faceted = FacetedEllipsoid.from_limit_surface(ls)
    # A load lies on a facet when its centre of rotation (-vy/w, vx/w) is a support point.
    units = np.array([ls.max_force, ls.max_force, ls.max_moment])
    twists = ls.motion(mesh.reshape(-1, 3) * units)
    with np.errstate(divide="ignore", invalid="ignore"):
        cor = np.column_stack([-twists[:, 1], twists[:, 0]]) / twists[:, 2:3]
    gap = np.min(np.linalg.norm(cor[:, None, :] - xy[None, :, :], axis=2), axis=1)
    on_facet = (gap < 1e-6 * radius).reshape(mesh.shape[:2])

    fig = Figure(figsize=(6.0, 8.0))
    top = fig.add_subplot(2, 1, 1)
    top.scatter(xy[:, 0] * 1e3, xy[:, 1] * 1e3, s=200, c="C3")
    for k, (x, y) in enumerate(xy):
        top.annotate(
            f"N/3 at point {k + 1}", (x * 1e3, y * 1e3), xytext=(8, 8), textcoords="offset points"
        )
    top.set_aspect("equal")
    top.set_xlim(-1.6 * radius * 1e3, 1.6 * radius * 1e3)
    top.set_ylim(-1.0 * radius * 1e3, 1.5 * radius * 1e3)
    top.set_xlabel("x [mm]")
    top.set_ylabel("y [mm]")
    top.set_title("Fig. 6: three isolated contact points")
    bottom = fig.add_subplot(2, 1, 2, projection="3d")
    colours = np.where(on_facet[..., None], to_rgba("C3"), to_rgba("C0"))
    bottom.plot_surface(
        mesh[..., 0],
        mesh[..., 1],
        mesh[..., 2],
        facecolors=colours,
        linewidth=0.1,
        edgecolor="0.3",
        shade=True,
    )
    bottom.set_xlabel("f_x / f_max")
    bottom.set_ylabel("f_y / f_max")
    bottom.set_zlabel("m / m_max")
    bottom.set_box_aspect((1, 1, 1))
    bottom.set_title(
        f"limit surface; red: the {2 * len(faceted.points)} facets (rotation about a point)"
    )
    fig.tight_layout()
    return fig


FIGURES = {
    "fig2_cor_and_limit_curve.png": figure_2,
    "fig3_normalised_limit_curves.png": figure_3,
    "fig4_rectangle_limit_surface.png": figure_4,
    "fig5_rectangle_sections.png": figure_5,
    "fig6_point_supports.png": figure_6,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument(
        "--out",
        type=Path,
        default=Path(__file__).resolve().parent / "output",
        help="output directory (created if missing)",
    )
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for name, build in FIGURES.items():
        path = args.out / name
        _save(build(), path)
        print(path)


if __name__ == "__main__":
    main()
