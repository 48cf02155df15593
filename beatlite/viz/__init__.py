"""Skeleton plots and animations: matplotlib always, pyvista renders behind a subprocess probe.

Submodules are imported lazily (``import beatlite.viz`` imports neither pyplot,
pyvista nor torch); the names below are importable from ``beatlite.viz``.

==========================  ==================================================================
``style``                    one figure style (:func:`figure_style`, :data:`STYLE`), :func:`save_figure`,
                             :func:`system_colour`, :func:`legend_outside`
``check``                    :func:`check_figure` (empty panels, text under 8 px, two series in one
                             colour), run by :func:`save_figure` on every figure it saves
``plot3d``                   :func:`plot_frame`, :func:`plot_filmstrip`, :func:`plot_views`,
                             :func:`plot_trajectories`, :func:`plot_keyframes` (matplotlib 3D),
                             :func:`plot_bone_levels` (what each hierarchy level adds, 2D)
``animation``                :func:`animate_skeletons` (GT | CaMN | HA2G side by side, one scale;
                             :class:`Timeline`, words, :class:`FacePanel`) -> :class:`SkeletonAnimation`
                             (inline JS/HTML, ``.save_as`` GIF/MP4/HTML, 960 px wide)
``face``                     :func:`plot_blendshapes` (ARKit heat map / bars, by name),
                             :func:`plot_blendshape_curves` (the most active ones over time)
``charts``                   :func:`plot_training_curves`, :func:`plot_scores` (bars, outliers cut),
                             :func:`plot_score_scatter` (labelled points), :func:`plot_effects`
                             (ablation changes, paper vs ours ± error), :func:`plot_signals`
                             (curves + event lines + markers), :func:`plot_waveform` (amplitude, words, onsets),
                             :func:`plot_log_mel` (spectrogram, level bar, event lines)
``figures``                  multi-panel figures of notebooks 00-04: :func:`plot_corpus_overview`,
                             :func:`plot_transcript`, :func:`plot_annotations`, :func:`plot_onsets`,
                             :func:`plot_beat_curves`, :func:`plot_spread`
``render``                   pyvista: :func:`render_frame`, :func:`render_animation`, :func:`show_skeleton`
``probe``                    :func:`probe_offscreen`, :func:`use_pyvista` (subprocess probe, cached)
``bvh_export``               :func:`motion_from_subset`, :func:`export_bvh` (Blender import steps)
==========================  ==================================================================

Rendering backends: pyvista needs an off-screen OpenGL (EGL or OSMesa on a
headless Linux, see :mod:`beatlite.viz.probe` and ``scripts/system_deps.sh``);
when it is missing every pyvista function warns once and draws with matplotlib.
``BEATLITE_PYVISTA=off`` forces matplotlib.

Taught in notebooks/08_visualisation_3d.ipynb (seeing gestures), sections 1-6.
"""

from __future__ import annotations

import importlib
from typing import Any

_SUBMODULES = (
    "style",
    "check",
    "plot3d",
    "animation",
    "face",
    "charts",
    "figures",
    "render",
    "probe",
    "bvh_export",
)
_EXPORTS: dict[str, str] = {
    "STYLE": "style",
    "GROUP_COLOURS": "style",
    "SYSTEM_COLOURS": "style",
    "figure_style": "style",
    "save_figure": "style",
    "system_colour": "style",
    "system_colours": "style",
    "legend_outside": "style",
    "check_figure": "check",
    "FigureProblem": "check",
    "plot_frame": "plot3d",
    "plot_filmstrip": "plot3d",
    "plot_views": "plot3d",
    "plot_trajectories": "plot3d",
    "plot_keyframes": "plot3d",
    "plot_bone_levels": "plot3d",
    "animate_skeletons": "animation",
    "save_animation": "animation",
    "SkeletonAnimation": "animation",
    "Timeline": "animation",
    "FacePanel": "animation",
    "plot_training_curves": "charts",
    "plot_scores": "charts",
    "plot_score_scatter": "charts",
    "plot_effects": "charts",
    "plot_signals": "charts",
    "plot_waveform": "charts",
    "plot_log_mel": "charts",
    "plot_corpus_overview": "figures",
    "plot_transcript": "figures",
    "plot_annotations": "figures",
    "plot_onsets": "figures",
    "plot_beat_curves": "figures",
    "plot_spread": "figures",
    "plot_blendshape_curves": "face",
    "plot_blendshapes": "face",
    "render_frame": "render",
    "render_animation": "render",
    "show_skeleton": "render",
    "probe_offscreen": "probe",
    "use_pyvista": "probe",
    "motion_from_subset": "bvh_export",
    "export_bvh": "bvh_export",
}

__all__ = [*_SUBMODULES, *_EXPORTS]


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"beatlite.viz.{name}")
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"beatlite.viz.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module 'beatlite.viz' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
