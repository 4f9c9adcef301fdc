"""The visibility bake (occlusion of the environment light, alight.core.visibility) for the
editor's view, made away from its frames.

The bake is per vertex and view-independent, so the editor's moving camera draws the same baked
parts as ``alight render``'s still; but it is ray-traced in numpy and Embree, which hold the GIL
for seconds (DamagedHelmet: 0.15 s to decide 'auto', 5.8 s to bake, 1.9 s for the suns on the
occluders, 3.2 s for the sky weight's rays and 1.8 s for the weight itself, cold on this 2-core
machine). So the child process ``python -m alight.frontends.editor.occlusion_bake`` (worker_process.py)
makes every piece the view's draw needs into the disk bake cache the renderer reads
(alight.render.visibility_parts: ``cached_visibility``, ``cached_sun_bounce``,
``OcclusionParts.cached_sky_weight``, ``cached_occluder_materials``), and the view draws without occlusion until it answers;
then the editor's renderer loads them (a cache read, tens of ms). A new mesh (or occlusion mode,
or a material that lets light through) supersedes a running bake; a turned environment or
another map only remakes the suns' and sky's terms, the view keeping the last ones meanwhile
(``OcclusionParts.hold_lighting``).
"""

from __future__ import annotations

import dataclasses
import os
import pickle
import sys
import time
from dataclasses import dataclass

import numpy as np


@dataclass
class OcclusionJob:
    mesh: object            # alight.core.mesh.Mesh; None: the one last sent under mesh_token
    mesh_token: int
    mode: str               # 'auto' or 'on'
    through: tuple | None   # visibility_parts.light_through of the view's scene
    suns: np.ndarray        # (K, 3) world directions of the environment's compact sources
    texels: np.ndarray | None   # visibility_parts.environment_texels (None: no environment drawn)
    digest: str
    rotation_deg: float
    out: str                # the child writes {'wanted': bool} here (a pickle)
    materials: tuple | None = None   # visibility_parts.occluder_materials of the view's scene


@dataclass
class _Sent:
    key: tuple       # (mesh key, lighting key) this job makes
    job_id: int
    out: object      # pathlib.Path
    started: float = 0.0   # time.monotonic() when sent: the status row counts the seconds


class OcclusionBake:
    """The parent's side. Each frame ``view_scene`` gives the scene the view draws (its
    occlusion 'off' until the cache holds the bake) and whether to hold the last lighting;
    ``step`` takes the child's answers (True: the view must draw again)."""

    def __init__(self):
        self._worker = None
        self._running: _Sent | None = None
        self._next: tuple | None = None     # a lighting key to make once the running job ends
        self._ready: set = set()            # full keys the cache holds
        self._decided: dict = {}            # mesh key -> wanted (the child's wants_occlusion)
        self._meshes: dict = {}             # id -> mesh, so an id in a key is never reused
        self._sent_token = None
        self.status = ""                    # the status row's words ('' when nothing is baking)
        self.jobs = 0                       # bakes asked of the child (tests read it)
        self.last_seconds = 0.0             # the child's last job's wall time

    def view_scene(self, win, scene, maps, whole: bool = False):
        """(the scene to draw, whether the renderer holds the last suns' and sky's values).
        ``whole``: the view drawn for a file (a screenshot, ``alight edit --screenshot``), which
        waits for a running bake as it waits for the IBL's (``finish_bake``) and is drawn with
        occlusion as ``alight render`` draws it (the renderer bakes what the cache lacks)."""
        mode = scene.occlusion
        if mode in ("off", "gtao") or scene.mesh is None or scene.mesh.lod_sphere is not None:   # (gtao: no bake)
            self.status = ""
            return scene, False
        from alight.render.bindings import sun_world_directions
        from alight.render.visibility_parts import environment_texels, light_through, occluder_materials

        mesh = scene.mesh
        if id(mesh) not in self._meshes:
            self._forget_meshes(keep={id(mesh)} | ({self._running.key[0][0]} if self._running else set()))
            self._meshes[id(mesh)] = mesh
            self._sent_token = None   # a new object, though it may have a forgotten mesh's id: sent whole
        mesh_key = (id(mesh), mode, light_through(scene))
        if whole:
            self.finish(win)
        wanted = self._decided.get(mesh_key)
        if wanted is False:
            # 'auto' found it occludes too little of itself (the same picture as 'off'), or the
            # child failed (said in the status row): drawn without, never baked in this process.
            self.status = ""
            return dataclasses.replace(scene, occlusion="off"), False
        if whole:
            return scene, False
        suns = sun_world_directions(scene, maps)
        texels, digest = environment_texels(win.renderer.shaders, maps) if maps is not None else (None, "")
        rotation = float(scene.env_rotation_deg)
        # The parts' materials as the occluders' pass reads them: a colour edit remakes that pass
        # only (a few factors each: cheap to compare every frame).
        materials = occluder_materials(scene)
        light_key = (tuple(np.round(suns, 5).ravel()), digest, round(rotation % 360.0, 6), materials)
        key = (mesh_key, light_key)
        if key in self._ready:
            self.status = ""
            return scene, False
        job = (mesh, mode, mesh_key[2], suns, texels, digest, rotation, materials)
        if self._running is None or self._running.key[0] != mesh_key:
            self._submit(key, job)     # a new mesh or mode supersedes the running bake
        elif self._running.key != key:
            self._next = (key, job)    # the lighting of the mesh being baked: after it
        if wanted:   # the bake is in the cache: drawn with the last lighting meanwhile
            self.status = "occlusion: the environment's light on it follows in a moment"
            return scene, True
        # The seconds so far: a big mesh's bake takes minutes, and a row that never changes
        # looked stuck to a new user.
        running = self._running
        seconds = f" ({time.monotonic() - running.started:.0f} s)" if running is not None and running.started else ""
        self.status = f"baking occlusion{seconds}: the view is drawn without it meanwhile"
        return dataclasses.replace(scene, occlusion="off"), False

    @staticmethod
    def _say_screen_occlusion(win, mesh, mode: str, wanted: bool) -> None:
        """'auto' on a mesh too big to bake draws it with screen-space GTAO: the status row says
        so, as the command line's warning does (a new user saw only 'baking occlusion')."""
        from alight.core.visibility import AUTO_MAX_VERTICES, screen_occlusion

        if not screen_occlusion(mesh, mode, wanted):
            return
        note = (f"occlusion: gtao (screen space) for this mesh of more than {AUTO_MAX_VERTICES} vertices; "
                f"'on' bakes it")
        state = win.state
        if note not in state.message:
            state.message = f"{state.message}; {note}" if state.message else note

    def _forget_meshes(self, keep: set) -> None:
        """Drop what is known of meshes no longer shown, so a new mesh given a dead one's id is
        never taken for it (the cache on disk keeps their bakes)."""
        self._meshes = {i: m for i, m in self._meshes.items() if i in keep}
        self._ready = {k for k in self._ready if k[0][0] in keep}
        self._decided = {k: v for k, v in self._decided.items() if k[0] in keep}

    def _submit(self, key, job) -> None:
        from alight.frontends.editor.worker_process import WorkerProcess

        if self._worker is None:
            self._worker = WorkerProcess("alight.frontends.editor.occlusion_bake")
        mesh, mode, through, suns, texels, digest, rotation, materials = job
        # The mesh is sent once, then named by its token; and its geometry only: the bake and its
        # cache key (visibility.mesh_digest) read nothing else, and DamagedHelmet's decoded
        # textures made an 85 MB pickle (0.9 MB without), written in the frame that sends it.
        token = id(mesh)
        send = token != self._sent_token
        self._sent_token = token
        # Of the material only doubleSided goes along: which parts are single-sided is the bake's
        # too (alight.core.mesh.single_sided; a glTF part without a material is single-sided).
        geometry = dataclasses.replace(mesh, parts=[dataclasses.replace(p, material=_sidedness(p.material))
                                                    for p in mesh.parts],
                                       cameras=[], lights=[]) if send else None
        out = self._worker.scratch_file(f"occlusion-{self.jobs}.pickle")
        job_id = self._worker.submit(OcclusionJob(mesh=geometry, mesh_token=token, mode=mode,
                                                  through=through, suns=np.asarray(suns, np.float64),
                                                  texels=texels, digest=digest, rotation_deg=rotation,
                                                  out=str(out), materials=materials))
        self._running, self._next = _Sent(key, job_id, out, time.monotonic()), None
        self.jobs += 1

    def step(self, win, answers=None) -> bool:
        """The child's answers (``answers``: those a wait took): True when the view should draw
        again (a bake became ready)."""
        if self._worker is None or self._running is None:
            return False
        redraw = False
        for job_id, word, text in (self._worker.answers() if answers is None else answers):
            sent = self._running
            if sent is None or job_id != sent.job_id or word == "progress":
                continue
            self._running = None
            mesh_key = sent.key[0]
            mesh = self._meshes.get(mesh_key[0])
            if word == "done":
                try:
                    with open(sent.out, "rb") as f:
                        answer = pickle.load(f)
                except (OSError, pickle.UnpicklingError, EOFError):
                    answer = None
                sent.out.unlink(missing_ok=True)
                if answer is not None and mesh is not None:
                    self._decided[mesh_key] = answer["wanted"]
                    # The renderer casts no rays of its own to decide 'auto' again.
                    win.renderer.visibility_parts.decide(mesh, mesh_key[1], answer["wanted"])
                    self._ready.add(sent.key)
                    self.last_seconds = float(text or 0.0)
                    redraw = True
                    self._say_screen_occlusion(win, mesh, mesh_key[1], answer["wanted"])
            elif word == "error":
                # Drawn without occlusion, and said once ('on' needs embreex, a bake that failed).
                self._decided[mesh_key] = False
                self._sent_token = None   # the child may have restarted: send the mesh again
                from alight.errors import AlightError

                win.state.fail(AlightError(text if "occlusion" in text else f"occlusion: {text}"))
                redraw = True
            else:   # cancelled (a newer job superseded it)
                pass
        if self._running is None and self._next is not None:
            key, job = self._next
            if key not in self._ready and self._decided.get(key[0]) is not False:
                self._submit(key, job)
            self._next = None
        return redraw

    def finish(self, win, timeout_s: float = 600.0) -> None:
        """Wait for the running bake (and the lighting queued after it)."""
        while self._running is not None and self._worker is not None:
            self.step(win, self._worker.wait(self._running.job_id, timeout_s))
        win.renderer.visibility_parts.hold_lighting = False   # the terms are in the cache now

    def close(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None


# --- the child process ---------------------------------------------------------------------------

def main() -> int:
    from alight.core.visibility import auto_too_big, embree_available, wants_occlusion
    from alight.frontends.editor.worker_process import serve
    from alight.ibl.bake_cache import BakeCache
    from alight.render.visibility_parts import (OcclusionParts, cached_occluder_materials, cached_sun_bounce,
                                                cached_visibility)

    cache = BakeCache()   # the renderer's own (the same folder: ALIGHT_CACHE_DIR or the user's)
    # The same settings as the editor's renderer (ForwardRenderer's OcclusionParts): the same keys.
    parts = OcclusionParts(None, cache)
    have = {"token": None, "mesh": None}

    def handle(job: OcclusionJob, progress, superseded) -> bool:
        if job.mesh is not None:
            have["token"], have["mesh"] = job.mesh_token, job.mesh
        elif have["token"] != job.mesh_token:
            raise RuntimeError(f"the mesh named {job.mesh_token} was never sent")
        mesh = have["mesh"]
        wanted = wants_occlusion(mesh, job.mode)
        # 'auto' draws without where the bake cannot run or the mesh is too big (the renderer says
        # so once); nothing to bake then.
        bake = wanted and not (job.mode == "auto" and (not embree_available() or auto_too_big(mesh)))
        if bake:
            steps = ((lambda b: cached_sun_bounce(mesh, b, job.suns, cache, parts.rays, parts.edge_fraction,
                                                  parts.max_vertices, job.through)),
                     (lambda b: None if job.texels is None else
                      parts.cached_sky_weight(mesh, b, job.texels, job.digest, job.rotation_deg, job.through)),
                     (lambda b: None if job.materials is None else
                      cached_occluder_materials(mesh, b, job.materials, cache, parts.rays, parts.edge_fraction,
                                                parts.max_vertices, job.through)))
            if superseded():
                return False
            baked = cached_visibility(mesh, cache, parts.rays, parts.edge_fraction, parts.max_vertices, job.through)
            progress(0.5)
            for step in steps:
                if superseded():
                    return False
                step(baked)
        with open(job.out + ".tmp", "wb") as f:
            pickle.dump({"wanted": bool(wanted)}, f)
        os.replace(job.out + ".tmp", job.out)
        return True

    return serve(handle)


def _sidedness(material):
    """A bare FileMaterial holding ``material``'s doubleSided only (None stays None)."""
    from alight.core.mesh import FileMaterial

    return None if material is None else FileMaterial(double_sided=bool(material.double_sided))


if __name__ == "__main__":
    sys.exit(main())

