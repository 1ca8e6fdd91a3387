"""Indoor digital twins: the storeys, rooms, corridors, doors and entrances of a scanned or
modelled building, from its point cloud.

``find_interior(points)`` returns an :class:`Interior`: :mod:`.storeys` finds the floor levels,
:mod:`.heading` which way the walls run, :mod:`.plan` each storey's walls, outline and floor
on a grid along them, :mod:`.rooms` cuts the free space into rooms and tells corridors and
halls, :mod:`.doors` finds where rooms meet each other and the outside; a room no door leads
into is a void. A modelled building's mesh is read as the cloud :func:`surface_points`
samples on its surfaces (:mod:`.surface`).

scikit-image is a dependency for the segmenting: its watershed regrows the rooms, its
morphology (discs, skeletons) and contours shape and outline them; with scipy.ndimage's
distance transforms and labelling. Both are imported when called.
"""

from __future__ import annotations

from astralis_des.importers.indoor.doors import FoundDoor
from astralis_des.importers.indoor.interior import Interior, find_interior
from astralis_des.importers.indoor.plan import Plan
from astralis_des.importers.indoor.rooms import FoundRoom
from astralis_des.importers.indoor.storeys import Storey, find_storeys
from astralis_des.importers.indoor.surface import surface_points

__all__ = ["FoundDoor", "FoundRoom", "Interior", "Plan", "Storey", "find_interior",
           "find_storeys", "surface_points"]
