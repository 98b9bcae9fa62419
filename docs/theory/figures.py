"""Draws the two figures of the theory page (docs/theory.md).

    /usr/bin/python3 docs/theory/figures.py

writes docs/theory/statuses.png (the four status regions of the augmented multiplier
sigma = lambda + r d, and Phi on each) and docs/theory/transfer.png (the weights of P and Q on
a refined contact edge). Only matplotlib is needed.
"""

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent


def statuses(mu=0.5):
    fig, ax = plt.subplots(figsize=(6.2, 4.4))
    L = 2.0
    # sigma_t horizontal, sigma_n vertical (compression below the axis).
    gap = Polygon([(-L, 0), (L, 0), (L, L * 0.6), (-L, L * 0.6)], color="#d9d9d9")
    stick = Polygon([(0, 0), (mu * L, -L), (-mu * L, -L)], color="#9ecae1")
    fwd = Polygon([(0, 0), (L, 0), (L, -L), (mu * L, -L)], color="#fdae6b")
    bwd = Polygon([(0, 0), (-L, 0), (-L, -L), (-mu * L, -L)], color="#a1d99b")
    for p in (gap, stick, fwd, bwd):
        ax.add_patch(p)
    ax.plot([0, mu * L], [0, -L], "k", lw=1)
    ax.plot([0, -mu * L], [0, -L], "k", lw=1)
    ax.axhline(0, color="k", lw=1)
    ax.axvline(0, color="k", lw=0.5, ls=":")
    ax.text(0, 0.3 * L, "0 gap:  $\\Phi = 0$,  $M = 0$", ha="center", va="center")
    ax.text(0, -0.72 * L, "1 stick\n$\\Phi = \\sigma$\n$M = I$", ha="center", va="center")
    ax.text(0.68 * L, -0.45 * L,
            "2 slip forward\n$\\Phi_t = \\mu|\\sigma_n|$\n$\\Phi_n = \\sigma_n$",
            ha="center", va="center")
    ax.text(-0.68 * L, -0.45 * L,
            "3 slip backward\n$\\Phi_t = -\\mu|\\sigma_n|$\n$\\Phi_n = \\sigma_n$",
            ha="center", va="center")
    ax.text(mu * L * 0.55, -0.55 * L, "$|\\sigma_t| = -\\mu\\sigma_n$", rotation=-63,
            ha="left", va="center", fontsize=8)
    ax.set_xlim(-L, L)
    ax.set_ylim(-L, 0.6 * L)
    ax.set_xlabel("$\\sigma_t = \\lambda_t + r\\,d_t$")
    ax.set_ylabel("$\\sigma_n = \\lambda_n + r\\,d_n$")
    ax.set_title(f"Status regions of the augmented multiplier ($\\mu$ = {mu})")
    ax.set_xticks([])
    ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(HERE / "statuses.png", dpi=110)
    plt.close(fig)


def transfer():
    fig, axes = plt.subplots(2, 1, figsize=(6.4, 3.6), sharex=True)
    xs_coarse = [0, 2, 4]
    xs_fine = [0, 1, 2, 3, 4]
    for ax, title, w_vertex, w_mid in (
        (axes[0], "P (displacements): an intrinsic field", "1", "1/2 + 1/2"),
        (axes[1], "Q (multipliers, nodal forces): the paper's rule", "1/2", "1/4 + 1/4"),
    ):
        ax.plot([0, 4], [1, 1], "k-", lw=1)
        ax.plot([0, 4], [0, 0], "k-", lw=1)
        ax.plot(xs_coarse, [1] * 3, "ks", ms=7)
        ax.plot(xs_fine, [0] * 5, "o", color="#3182bd", ms=6)
        for x in xs_coarse:
            ax.annotate("", xy=(x, 0.08), xytext=(x, 0.92),
                        arrowprops=dict(arrowstyle="->", color="#636363"))
            ax.text(x + 0.06, 0.5, w_vertex, fontsize=9)
        for x in (1, 3):
            for s in (-1, 1):
                ax.annotate("", xy=(x, 0.08), xytext=(x + s, 0.92),
                            arrowprops=dict(arrowstyle="->", color="#e6550d"))
            ax.text(x, -0.22, w_mid, fontsize=9, color="#e6550d", ha="center", va="center")
        ax.text(-0.35, 1, "H", va="center")
        ax.text(-0.35, 0, "h", va="center")
        ax.set_title(title, fontsize=10)
        ax.set_ylim(-0.4, 1.3)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(HERE / "transfer.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    statuses()
    transfer()
