"""The figures' one writer: matplotlib on its file backend, the shared resolution, and PNGs laid
out, written atomically (with the user's umask, as every output of the library) and closed.

Every PNG of the library (mission maps and MOC, radio maps, plan figures, flights, campaign
reports) is drawn on :func:`pyplot` and written by :func:`save_png`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from searchtrack.core.files import atomic_path

DPI = 110
"""Resolution of the library's figures (dots per inch)."""


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (no display needed), imported
    on first use so that modules which draw stay cheap to import."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig: Any, path: str | Path, *, tight_bbox: bool = False,
             dpi: float | None = None) -> Path:
    """Lay out ``fig``, write it to ``path`` as PNG (atomically) and close it.

    Parameters
    ----------
    tight_bbox
        Crop the saved image to the drawn artists (legends outside the axes included).
    dpi
        Resolution; the figure's own when ``None``.
    """
    plt = pyplot()
    out = Path(path)
    try:
        fig.tight_layout()
        with atomic_path(out) as temp:
            fig.savefig(temp, format="png", dpi=dpi if dpi is not None else "figure",
                        bbox_inches="tight" if tight_bbox else None)
    finally:
        plt.close(fig)
    return out
