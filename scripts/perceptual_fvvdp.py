"""FovVideoVDP (Mantiuk et al. 2021, the authors' pyfvvdp) over `fovea quality` folders.

Each run's evaluated frames, as displayed (frame_NNNN.png), are judged against the converged
references as displayed (reference_<camera>_NNNN.png, the same exposure and tone curve) as a video
at the headset's refresh, foveated on each frame's gaze. The display is the headset's eye: the
render's pixels across the left eye's FOV (a tangent plane, as fovea renders it) and HTC Vive
Pro's photometry from pyfvvdp's display list (133.3 cd/m² peak, 0.1 cd/m² black), the one
head-mounted display there. Writes DIR/perceptual.json and DIR/perceptual.md (temp file +
rename). Run through scripts/perceptual, which makes the Python environment.
"""

import json
import math
import os
import sys
import tempfile
import time

import numpy as np
import torch
from PIL import Image

import pyfvvdp
from pyfvvdp.fvvdp_display_model import fvvdp_display_geometry, fvvdp_display_photo_eotf

PEAK_CD_M2 = 133.3
BLACK_CD_M2 = 0.1
# Any distance: only the angles matter (the geometry is the FOV's tangent plane).
DISTANCE_M = 1.0


class Refused(Exception):
    pass


def read_png(path, width, height):
    try:
        image = np.asarray(Image.open(path).convert("RGB"))
    except (OSError, ValueError) as e:
        raise Refused(f"{path}: cannot read the image ({e})")
    if image.shape[:2] != (height, width):
        raise Refused(
            f"{path}: {image.shape[1]}×{image.shape[0]} pixels, quality.json says {width}×{height}"
        )
    return image


def symmetric_fov_deg(left, right):
    """The horizontal FOV of a symmetric tangent plane as wide as the eye's (asymmetric) one."""
    half_width = (math.tan(math.radians(right)) - math.tan(math.radians(left))) / 2.0
    return 2.0 * math.degrees(math.atan(half_width))


def load_report(folder):
    path = os.path.join(folder, "quality.json")
    try:
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
    except OSError as e:
        raise Refused(f"{path}: cannot read it ({e.strerror})")
    except json.JSONDecodeError as e:
        raise Refused(f"{path}: not JSON (line {e.lineno}: {e.msg})")
    for key in ("width", "height", "refresh_hz", "eye_fov_deg", "runs"):
        if key not in report:
            raise Refused(
                f"{path}: no `{key}` (a quality.json of an older fovea? run fovea quality again)"
            )
    for i, run in enumerate(report["runs"]):
        for key in ("run_dir", "camera", "frames", "gaze"):
            if not run.get(key):
                raise Refused(f"{path}: runs[{i}] has no `{key}`")
    return report


def reference_name(report, camera, frame):
    if report.get("eyes") == "both":
        return f"reference_{camera}_left_{frame:04}.png"
    return f"reference_{camera}_{frame:04}.png"


def metric_for(report):
    width, height = report["width"], report["height"]
    left, right, _down, _up = report["eye_fov_deg"]
    geometry = fvvdp_display_geometry(
        (width, height), distance_m=DISTANCE_M, fov_horizontal=symmetric_fov_deg(left, right)
    )
    photometry = fvvdp_display_photo_eotf(
        PEAK_CD_M2, contrast=PEAK_CD_M2 / BLACK_CD_M2, EOTF="sRGB", E_ambient=0
    )
    metric = pyfvvdp.fvvdp(
        display_photometry=photometry,
        display_geometry=geometry,
        foveated=True,
        quiet=True,
        device=torch.device("cpu"),
    )
    return metric, geometry


def score_run(folder, report, run, metric):
    width, height = report["width"], report["height"]
    run_folder = os.path.join(folder, run["run_dir"])
    frames = run["frames"]
    tests = [read_png(os.path.join(run_folder, f"frame_{f:04}.png"), width, height) for f in frames]
    # A still camera has one reference (frame 0) for every frame.
    reference_frames = frames if run["camera"] == "moving" else [0] * len(frames)
    cache = {}
    references = []
    for f in reference_frames:
        if f not in cache:
            cache[f] = read_png(os.path.join(folder, reference_name(report, run["camera"], f)), width, height)
        references.append(cache[f])
    test = np.stack(tests)
    reference = np.stack(references)
    fps = report["refresh_hz"] if len(frames) > 1 else 0

    def jod(gazes):
        fixation = torch.tensor(np.asarray(gazes, dtype=np.float32))
        with torch.no_grad():
            q, _ = metric.predict(test, reference, dim_order="FHWC", frames_per_second=fps, fixation_point=fixation)
        return float(q)

    scored = {"jod": jod(run["gaze"])}
    # With the latency model: also judged where the eye is when each frame is shown (frames
    # without a true gaze keep the rendered one).
    if run.get("gaze_true"):
        truth = [t if t is not None else g for t, g in zip(run["gaze_true"], run["gaze"])]
        scored["jod_true_gaze"] = jod(truth)
    return scored


def write_atomic(path, text):
    folder = os.path.dirname(path) or "."
    fd, temp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(temp, path)
    except BaseException:
        os.unlink(temp)
        raise


def label(run):
    return f"{run['method']} + {run['denoiser']}, taa {run['taa']}"


def score_folder(folder):
    report = load_report(folder)
    metric, geometry = metric_for(report)
    runs = []
    for run in report["runs"]:
        started = time.time()
        scored = score_run(folder, report, run, metric)
        entry = {
            key: run.get(key)
            for key in ("run_dir", "camera", "method", "denoiser", "taa", "stereo_noise", "samples_traced", "rays_traced", "frame_gpu_ms", "frame_flip")
        }
        entry.update(scored)
        runs.append(entry)
        print(f"  {run['run_dir']}: {scored['jod']:.3f} JOD ({time.time() - started:.0f} s)", flush=True)
    out = {
        "metric": "FovVideoVDP",
        "pyfvvdp_version": getattr(pyfvvdp, "__version__", None) or "1.2",
        "foveated": True,
        "scene": report.get("scene"),
        "width": report["width"],
        "height": report["height"],
        "headset": report.get("headset"),
        "gaze_source": report.get("gaze_source"),
        "frames_per_second": report["refresh_hz"],
        "pixels_per_degree": float(geometry.get_ppd()),
        "display_peak_cd_m2": PEAK_CD_M2,
        "display_black_cd_m2": BLACK_CD_M2,
        "runs": runs,
    }
    write_atomic(os.path.join(folder, "perceptual.json"), json.dumps(out, indent=2) + "\n")
    lines = [
        f"FovVideoVDP (foveated, each frame's gaze) — {out['scene']}, {out['width']}×{out['height']}, "
        f"{out['pixels_per_degree']:.1f} px/° at the centre, {out['frames_per_second']:g} Hz, gaze {out['gaze_source']}",
        "",
        "| camera | method + denoiser, TAA | samples / frame | GPU ms / frame | JOD |" + (" JOD at the true gaze |" if any("jod_true_gaze" in r for r in runs) else ""),
        "|---|---|---|---|---|" + ("---|" if any("jod_true_gaze" in r for r in runs) else ""),
    ]
    for r in runs:
        row = f"| {r['camera']} | {label(r)} | {r['samples_traced']} | {r['frame_gpu_ms']:.1f} | {r['jod']:.3f} |"
        if "jod_true_gaze" in r:
            row += f" {r['jod_true_gaze']:.3f} |"
        lines.append(row)
    table = "\n".join(lines) + "\n"
    write_atomic(os.path.join(folder, "perceptual.md"), table)
    print(table)


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: scripts/perceptual QUALITY_DIR…  (folders written by `fovea quality`)")
        return 0 if argv else 2
    torch.set_num_threads(max(1, os.cpu_count() or 1))
    for folder in argv:
        print(f"{folder}:", flush=True)
        try:
            score_folder(folder)
        except Refused as e:
            print(f"scripts/perceptual: {e}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
