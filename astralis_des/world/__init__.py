"""The world layer: geometry, the building model, routing, and the scene a run furnishes it
with (furniture, avatars, the target, moving obstacles). It imports only the foundations."""
