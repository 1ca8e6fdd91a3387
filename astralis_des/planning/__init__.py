"""Global planning: the world's occupancy as voxel and grid maps, and OMPL behind one adapter."""
