"""Flexfit: rigid-deformable parts for virtual assembly.

A part is a triangle mesh that moves as a rigid body until something presses on it; then it
becomes a mass-spring-damper model only in small zones around the contacts, deforms, restores
its shape and is rigid again. Parts are assembled with snap-fitting.

The C++ library's API (meshes, models, parts, worlds, scenes, sweeps, exports) comes from the
compiled module ``flexfit._flexfit``; ``flexfit.sweep`` runs a sweep on a Dask cluster.

    import flexfit
    run = flexfit.SceneRun(flexfit.load_scene("examples/ball_torus.toml"))
    mouth = run.world.part(run.body("mouth"))
    for _ in range(1000):
        run.step()
    print(mouth.zone_depths.max(), run.world.state_hash())
"""

from ._flexfit import *  # noqa: F401,F403  (the bindings: see help(flexfit._flexfit))
from ._flexfit import __doc__ as _bindings_doc  # noqa: F401
from .sweeps import sweep  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
