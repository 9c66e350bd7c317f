"""The ZYX Euler-angle singularity along a nominal path and in a running state (docs/model.md s.2).

The band, its checks and the chart's stiffening are defined beside the loop that stops in them,
:mod:`coopctrl.loop.euler_band` (the loop imports nothing of ``coopctrl.analysis``); this module keeps
the public names for the analysis layer and for users.
"""

from coopctrl.loop.euler_band import (
    CHART_PITCH_DEG,
    EULER_PITCH_MARGIN_DEG,
    NearSingularity,
    SingularityHit,
    chart_mode_share,
    check_nominal_path,
    closest_to_singularity,
    first_path_hit,
    fix_hint,
    hit_from_plant_error,
    margin_cos,
    node_pitches,
    nominal_path_pitches,
)

__all__ = ["CHART_PITCH_DEG", "EULER_PITCH_MARGIN_DEG", "NearSingularity", "SingularityHit", "chart_mode_share",
           "check_nominal_path", "closest_to_singularity", "first_path_hit", "fix_hint", "hit_from_plant_error",
           "margin_cos", "node_pitches", "nominal_path_pitches"]
