"""``alight batch --executor ray``: the batch's items on a Ray cluster.

Each Ray actor is one worker process holding its own EGL context, shader programs, loaded
meshes and bake cache (alight.frontends.batch_worker.render_item keeps them for the life of the process), so a
worker bakes each environment once however many items it renders. Items are handed out with
``ray.util.ActorPool.map_unordered``: a free actor takes the next item.

Where the cluster is: ``ray.init(address)``, with ``address`` from ``--ray-address`` or the
``RAY_ADDRESS`` environment variable ("auto" joins the cluster this machine belongs to, e.g.
after ``ray start --address=HEAD:6379``); with neither, a local Ray is started for the run.
Every node needs alight installed and EGL (Mesa or NVIDIA); local workers run this interpreter.
Outputs are written by the workers, so the output folder must be on a file system every node
sees (NFS or similar) for a multi-machine cluster.
"""

from __future__ import annotations

import os
from typing import Iterator

from alight.errors import AlightError


def execute(items: list, workers: int | None, address: str | None = None) -> Iterator[tuple[str, str | None, float]]:
    try:
        import ray
        from ray.util import ActorPool
    except ImportError:
        raise AlightError("--executor ray: Ray is not installed (pip install 'alight[ray]')") from None
    started_here = False
    if not ray.is_initialized():
        address = address or os.environ.get("RAY_ADDRESS")
        try:
            ray.init(address=address, include_dashboard=False,
                     log_to_driver=False, **({} if address else {"num_cpus": workers or os.cpu_count()}))
        except Exception as e:  # a wrong address, a cluster that is down: one line, not a traceback
            raise AlightError(f"--executor ray: cannot connect to Ray ({' '.join(str(e).split())})") from None
        started_here = True
    try:
        n = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        n = max(1, min(n, len(items)))
        actor_class = ray.remote(num_cpus=1)(_Worker)
        actors = [actor_class.remote() for _ in range(n)]
        pool = ActorPool(actors)
        ordered = sorted(items, key=lambda i: (i.environment, i.quality, i.mesh))
        for result in pool.map_unordered(lambda actor, item: actor.render.remote(item), ordered):
            yield result
    finally:
        if started_here:
            ray.shutdown()


class _Worker:
    """One process, one GL context: alight.frontends.batch_worker keeps the renderer in a module global."""

    def render(self, item):
        from alight.frontends.batch_worker import render_item

        return render_item(item)

    def pid(self) -> int:
        return os.getpid()
