"""HA2G's ablation switches (HA2G Tables 3-4), torch-free so that recipes and tables can read them.

Each entry maps an ablation name to overrides of :class:`beatlite.models.ha2g.HA2GConfig`;
``beatlite.train.recipes.HA2G_ABLATIONS`` derives the shipped checkpoint names from it
(``ha2g_tiny`` for ``full``, ``ha2g_tiny_<name>`` otherwise).

Rows of the paper (Sec. 4.5) and their switches:

======================  ======================================  ====================================
paper row               name                                    switch
======================  ======================================  ====================================
f_a^low only            ``single_audio``                        ``audio_mode="low"``
f_a^mid only            ``mid_only``                            ``audio_mode="mid"``
f_a^high only           ``high_only``                           ``audio_mode="high"``
w/o f_a-^high           ``no_high_negatives``                   ``contrastive_high_negatives=False``
w/o f_a-^low,mid        ``no_low_mid_negatives``                ``contrastive_neg_weight=0``
w/o text                ``no_text``                             ``use_text=False`` (and no
                                                                contrastive loss, which needs text)
HA2G-ASR                (none)                                  needs a pretrained ASR network
Holistic                ``holistic``                            ``hierarchical=False``
w/o hand hierarchy      ``no_hand_hierarchy``                   ``hand_hierarchy=False``
w/o body hierarchy      ``no_body_hierarchy``                   ``body_hierarchy=False``
Same audio f_a^h        ``same_audio``                          ``same_audio=True``
w/o L_phy               ``no_physical``                         ``use_physical=False``
(not in the paper)      ``no_contrastive``                      ``use_contrastive=False``
======================  ======================================  ====================================

HA2G-ASR (Table 3) replaces the audio learner by a pretrained ASR network trained on far more
data; it cannot be trained offline from ``data_samples/`` and has no switch. ``no_contrastive``
keeps the text input and drops only the contrastive loss (the paper has no such row; its "w/o
text" drops both).
"""

from __future__ import annotations

from typing import Any

ABLATIONS: dict[str, dict[str, Any]] = {
    "full": {},
    "holistic": {"hierarchical": False},
    "no_hand_hierarchy": {"hand_hierarchy": False},
    "no_body_hierarchy": {"body_hierarchy": False},
    "single_audio": {"audio_mode": "low"},
    "mid_only": {"audio_mode": "mid"},
    "high_only": {"audio_mode": "high"},
    "same_audio": {"same_audio": True},
    "no_high_negatives": {"contrastive_high_negatives": False},
    "no_low_mid_negatives": {"contrastive_neg_weight": 0.0},
    "no_text": {"use_text": False, "use_contrastive": False},
    "no_contrastive": {"use_contrastive": False},
    "no_physical": {"use_physical": False},
}
"""Ablation name -> :class:`~beatlite.models.ha2g.HA2GConfig` overrides (see the module docstring)."""
