"""The cost-table scheduler: a basic motion for every note (docs/scheduler.md).

Public API: :class:`OnlinePlanner` (live), :func:`plan_notes` (a file, driven
exactly as live), :class:`PlannedNote` and :class:`PlanReport`, and
:func:`load_plan_config` for the tables in motions/.
"""

from virja.plan.config import PlanConfig, default_config, load_plan_config, plan_config_from_table
from virja.plan.planner import OnlinePlanner, plan_notes, plan_notes_with_report, reveal_time
from virja.plan.types import DroppedNote, MovedNote, PlannedNote, PlanReport

__all__ = [
    "DroppedNote",
    "MovedNote",
    "OnlinePlanner",
    "PlanConfig",
    "PlanReport",
    "PlannedNote",
    "default_config",
    "load_plan_config",
    "plan_config_from_table",
    "plan_notes",
    "plan_notes_with_report",
    "reveal_time",
]
