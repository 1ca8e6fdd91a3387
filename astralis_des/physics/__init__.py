"""The physics fidelity's parts: the PyBullet client and the world in it (:mod:`.client`),
the hexacopter (:mod:`.hexacopter`), the Husky (:mod:`.husky`) and the walker (:mod:`.walker`).
Every PyBullet call passes its client's id, so that simulations run side by side."""

from astralis_des.physics.quiet import quiet_c_output

with quiet_c_output(2):  # PyBullet prints its build time on stderr as it loads: once, here,
    import pybullet as pb  # before any module of the package (or importer) imports it

__all__ = ["pb"]
