"""Times Embree (embreex, one core) on the rays `fovea bench --dump-rays` wrote and prints them
beside fovea's own rates from the same bench's report.json. See scripts/embree-rays."""
import glob
import json
import os
import sys
import time

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

REPEATS = 3  # the best of three: the first run pays page faults


def rays(path):
    r = np.fromfile(path, dtype=np.float32).reshape(-1, 8)
    return np.ascontiguousarray(r[:, 0:3]), np.ascontiguousarray(r[:, 4:7])


def mrays_per_s(scene, origins, directions):
    best = float("inf")
    for _ in range(REPEATS):
        start = time.perf_counter()
        scene.run(origins, directions)
        best = min(best, time.perf_counter() - start)
    return len(origins) / best * 1e-6


def main(folder):
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # one core, like the figures
    report = json.load(open(os.path.join(folder, "report.json")))
    print(f"fovea on {report['device']} against Embree 4 (embreex) on one CPU core, the same rays")
    print("| scene | size | rays | fovea primary / indirect Mrays/s | Embree primary / indirect Mrays/s | fovea / Embree |")
    print("|---|---|---|---|---|---|")
    for tri_path in sorted(glob.glob(os.path.join(folder, "rays_*.triangles.bin"))):
        stem = os.path.basename(tri_path)[len("rays_"):-len(".triangles.bin")]
        scene_name, size = stem.rsplit("-", 1)
        w, h = (int(v) for v in size.split("x"))
        triangles = np.fromfile(tri_path, dtype=np.float32).reshape(-1, 3, 3)
        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, triangles)
        embree = [mrays_per_s(scene, *rays(tri_path.replace(".triangles.", f".{kind}."))) for kind in ("primary", "indirect")]
        ours = [r for r in report["rays"] if os.path.splitext(os.path.basename(r["scene"]))[0] == scene_name and (r["width"], r["height"]) == (w, h)]
        fovea = [ours[0]["primary_mrays_per_s"], ours[0]["indirect_mrays_per_s"]] if ours else [float("nan")] * 2
        n = len(rays(tri_path.replace(".triangles.", ".primary."))[0])
        print(f"| {scene_name} | {w}×{h} | {n} | {fovea[0]:.2f} / {fovea[1]:.2f} | {embree[0]:.2f} / {embree[1]:.2f} | "
              f"{fovea[0] / embree[0]:.2f} / {fovea[1] / embree[1]:.2f} |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: scripts/embree-rays BENCH_OUT_DIR")
    main(sys.argv[1])
