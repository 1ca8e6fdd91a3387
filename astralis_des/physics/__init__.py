"""The physics fidelity's parts: the PyBullet client and the world in it (:mod:`.client`),
the hexacopter (:mod:`.hexacopter`), the Husky (:mod:`.husky`) and the walker (:mod:`.walker`).
Every PyBullet call passes its client's id, so that simulations run side by side."""
