"""``TrackSettings``: one plan where a per-floor mapping is expected means every floor."""

from __future__ import annotations

from sfw_gym.evaluation.fingerprints import TrackSettings
from sfw_gym.world.generator import generate_floorplan


def test_one_floorplan_is_the_plan_of_every_floor() -> None:
    plan, other = generate_floorplan(1), generate_floorplan(2)
    assert TrackSettings(floorplans=plan).plan_for(3) is plan
    assert TrackSettings(floorplans=plan).plan_for(None) is plan
    by_floor = TrackSettings(floorplans={0: plan, None: other})
    assert by_floor.plan_for(0) is plan and by_floor.plan_for(5) is other
    assert TrackSettings().plan_for(0) is None
