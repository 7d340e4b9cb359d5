"""The road network the Smart City Manager advises on: the one "next light and sign ahead"
(autodrive.core.road_rules, the C library the city driver uses too) on its map's sidecar
document. A car is placed on a lane from its pose (its route, when known, and its last lane
break ties), then the lanes ahead are walked along its route; distances are along the lanes
from the car's pose point (base_link, the rear-axle centre)."""

from __future__ import annotations

from pathlib import Path

from autodrive.core.road_rules import HORIZON_M, Ahead, Anchor, Lane, Place, RoadNet
from autodrive.maps import MapDescription
from autodrive.maps.sidecar import document

__all__ = ["HORIZON_M", "Ahead", "Anchor", "Lane", "Place", "RoadNet", "for_map"]


def for_map(m: MapDescription, build: Path | None = None) -> RoadNet:
    """The network of a map description (its sidecar document, as maps/<map>.json holds it),
    with the road rules library of build (when it has one)."""
    return RoadNet(document(m), str(m.source), build)
