"""Interfaces to other tools: a Gymnasium environment of our trials (the ``gym`` extra).

The last package of the flow: it may import every package before it. Importing
it registers ``AbstractMap/FindPlace-v0`` with Gymnasium (when installed), so

    import gymnasium
    env = gymnasium.make("sim.interfaces:AbstractMap/FindPlace-v0", world="zoo")

works with no import of ours: Gymnasium imports the module named before the
colon. (Gymnasium 1.0 removed the ``gymnasium.envs`` entry-point plugins that
would have done this on ``import gymnasium``.)
"""

from __future__ import annotations

ENV_ID = "AbstractMap/FindPlace-v0"
ENTRY_POINT = "sim.interfaces.gym_env:FindPlaceEnv"


def register_envs() -> None:
    """Register our environments with Gymnasium (again is harmless)."""
    import gymnasium

    if ENV_ID not in gymnasium.registry:
        gymnasium.register(id=ENV_ID, entry_point=ENTRY_POINT)


try:
    import gymnasium  # noqa: F401
except ModuleNotFoundError:  # the gym extra is not installed: nothing to register
    pass
else:
    register_envs()
