"""The mesh VAE's pipeline (the paper's Fig. 1) as a drawing of boxes and arrows (notebook 00).

One pure function, :func:`pipeline_diagram`, returns a matplotlib Figure; nothing is computed
from data. The drawing reads as the paper's Fig. 1 does: the top row goes from the meshes to the
latent code (the encoder side), the bottom row comes back from the latent code to meshes (the
decoder side), and every box names its equation, the library module that computes it and the
notebook that teaches it.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PipelineStep", "PIPELINE_STEPS", "pipeline_diagram"]


@dataclass(frozen=True)
class PipelineStep:
    """One box of the diagram: what it holds, the paper's equation, the library module, the notebook."""

    title: str
    paper: str
    module: str
    notebook: str


#: the top row, left to right: from the meshes to the latent code.
ENCODER_SIDE = (
    PipelineStep("meshes $\\mathbf{p}'$\n(one connectivity,\nreference $\\mathbf{p}$)", "Sec. 3", "data_synth\ncollection_io", "00, 11"),
    PipelineStep("deformation\ngradients $\\mathbf{T}_i$", "Eq. (1)", "deformation_gradient\ncotangent", "01"),
    PipelineStep("RIMD feature\n$\\{\\log dR_{ij};\\ \\mathbf{S}_i\\}$", "Eq. (2)", "rotations\nrimd", "02"),
    PipelineStep("normalised\nto [-0.9, 0.9]", "Eq. (3)", "normalization", "03"),
    PipelineStep("VAE encoder\n(fully connected)", "Eq. (4)", "vae\ntraining", "04"),
)
#: the latent code between the two rows.
LATENT = PipelineStep("latent code $z$\n(mean ± σ,\nsampled)", "Eq. (4)", "vae", "04-08")
#: the bottom row, right to left: from the latent code back to meshes.
DECODER_SIDE = (
    PipelineStep("VAE decoder\n(mirrors the encoder)", "Eq. (4)", "vae", "04"),
    PipelineStep("de-normalised\nfeature", "Eq. (3)", "normalization", "03"),
    PipelineStep("RIMD feature\n$\\{\\log dR_{ij};\\ \\mathbf{S}_i\\}$", "Eq. (2)", "rimd", "02"),
    PipelineStep("reconstructed\nmeshes", "Sec. 3", "reconstruction\n(least squares)", "02, 04"),
    PipelineStep("generation, interp.,\nembedding,\nexploration", "Secs. 4.5, 5", "generation, ...\nexploration", "05-10"),
)
PIPELINE_STEPS = ENCODER_SIDE + (LATENT,) + DECODER_SIDE

_ENCODER_COLOUR = "#dbe8f6"
_DECODER_COLOUR = "#f8e3d3"
_LATENT_COLOUR = "#e3f1dc"


def pipeline_diagram(width: float = 12.5, fontsize: float = 10.0):
    """The paper's Fig. 1 as boxes and arrows, with where each step lives in the course.

    Draws two rows of rounded boxes joined by arrows: the top row from the meshes through the
    deformation gradients (Eq. 1), the RIMD feature (Eq. 2) and its normalisation (Eq. 3) into the
    VAE's encoder; a latent-code box at the right end; the bottom row back from the decoder through
    the de-normalisation and the RIMD feature to reconstructed meshes, and on to what the course
    does with them (generation, interpolation, embedding, exploration). Each box carries its title
    (bold), the paper's equation or section, the library module(s) (monospace) and the notebook
    ("nb 01"). Encoder-side boxes are blue, decoder-side boxes orange, the latent code green.

    Parameters
    ----------
    width : float
        Figure width in inches (the height follows: ``0.4 * width``).
    fontsize : float
        Size of the box titles in points; the other lines are one point smaller, never below 9.

    Returns
    -------
    fig : matplotlib.figure.Figure
        Not registered with pyplot (display it, or ``fig.savefig``). Its single axes holds one
        ``FancyBboxPatch`` per step (``gid`` = ``"step-<k>"``) and one ``FancyArrowPatch`` per
        arrow (``gid`` = ``"arrow-<k>"``).
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

    if fontsize < 9:
        raise ValueError(f"fontsize must be at least 9 points (readable at the saved size), got {fontsize}")
    small = max(9.0, fontsize - 1.0)
    fig = Figure(figsize=(width, 0.4 * width), dpi=100)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0, 6.3)
    ax.set_ylim(0, 2.56)
    ax.set_axis_off()

    box_w, box_h = 0.92, 0.98
    top_y, bottom_y = 1.86, 0.66
    xs = [0.55 + 1.08 * k for k in range(5)]
    positions = [(x, top_y) for x in xs] + [(5.85, 0.5 * (top_y + bottom_y))] + [(x, bottom_y) for x in reversed(xs)]
    colours = [_ENCODER_COLOUR] * 5 + [_LATENT_COLOUR] + [_DECODER_COLOUR] * 5

    def draw(k, step, xy, colour):
        x, y = xy
        w = box_w if k != 5 else 0.8
        ax.add_patch(FancyBboxPatch((x - w / 2, y - box_h / 2), w, box_h, boxstyle="round,pad=0.0,rounding_size=0.06",
                                    fc=colour, ec="0.25", lw=1.2, gid=f"step-{k}"))
        ax.text(x, y + box_h / 2 - 0.05, step.title, ha="center", va="top", fontsize=fontsize, fontweight="bold")
        ax.text(x, y - 0.1, step.paper, ha="center", va="center", fontsize=small, color="0.2", style="italic")
        ax.text(x, y - 0.2, step.module, ha="center", va="top", fontsize=small, family="monospace", color="#1f3f73")
        ax.text(x + w / 2 - 0.04, y - box_h / 2 + 0.04, f"nb {step.notebook}", ha="right", va="bottom", fontsize=small,
                color="#7a2e0e")

    for k, (step, xy, colour) in enumerate(zip(PIPELINE_STEPS, positions, colours)):
        draw(k, step, xy, colour)

    def arrow(k, a, b, rad=0.0):
        ax.add_patch(FancyArrowPatch(a, b, arrowstyle="-|>", mutation_scale=16, lw=1.6, color="0.15",
                                     connectionstyle=f"arc3,rad={rad}", gid=f"arrow-{k}"))

    k = 0
    for i in range(4):  # top row, left to right
        arrow(k, (xs[i] + box_w / 2, top_y), (xs[i + 1] - box_w / 2, top_y))
        k += 1
    lx, ly = positions[5]
    arrow(k, (xs[4] + box_w / 2, top_y), (lx, ly + box_h / 2), rad=-0.3)
    k += 1
    arrow(k, (lx, ly - box_h / 2), (xs[4] + box_w / 2, bottom_y), rad=-0.3)
    k += 1
    for i in range(4, 0, -1):  # bottom row, right to left
        arrow(k, (xs[i] - box_w / 2, bottom_y), (xs[i - 1] + box_w / 2, bottom_y))
        k += 1
    ax.text(0.09, 2.52, "encoder side: from meshes to a latent code", ha="left", va="top", fontsize=small, color="#1f3f73")
    ax.text(0.09, 0.03, "decoder side: from a latent code back to meshes", ha="left", va="bottom", fontsize=small,
            color="#7a2e0e")
    return fig
