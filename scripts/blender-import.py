"""Opens the BVH files duet writes in Blender, each dancer at its true size, in one scene.

    blender --python scripts/blender-import.py -- PARTNER.bvh [USER.bvh ...] [--scale S]
        [--fps F] [--duet PATH] [--check]
    blender -b --python-exit-code 1 --python scripts/blender-import.py -- ... --check   (headless)

A BVH file cannot say its units, and Blender's importer reads every number as metres unless told
a scale. duet writes each file in the units it reads back for that skeleton (the source's: salsa
DAZ 1/0.768 m, CMU 0.056444 m, ...; docs/file-formats.md), and `duet inspect --json FILE` says
which ("metres_per_unit"): this script asks it for every file, so the partner and the user stand
at their true sizes even when their files use different units. --scale S (metres per file unit)
overrides that for all files; without duet on the PATH give --duet PATH or --scale.

Each file becomes one armature (named after the file), imported like the viewer check in
tests/viewers/blender_import_check.py: Y up (axis_forward -Z, axis_up Y), native Euler orders,
one Blender frame per BVH frame from frame 1. The scene runs at the files' frame rate (--fps F
for a header that is wrong, such as the raw CMU salsa files' 120) over the longest file.

Debian 12's Blender 3.4 cannot import any BVH as shipped (its importer opens files with mode
'rU', which Python 3.11 removed): the script patches that for the session, nothing else.

Prints one line per file and one for the scene ("blender-import: ..."). --check then verifies,
for every file, that its armature exists with one key per frame and that the dancer's extent over
all frames, read back from Blender's pose, is duet's (`duet inspect --json` bounding box, 5 mm):
an error (exit 1 with --python-exit-code 1) otherwise.
"""
import argparse
import builtins
import json
import math
import os
import shutil
import subprocess
import sys

import bpy

PREFIX = "blender-import: "


class ImportFailed(Exception):
    """Raised so that Blender reports it (and exits non-zero with --python-exit-code)."""


def patch_debian_importer():
    """Debian 12's blender 3.4.1 runs on Python 3.11, which removed the "U" file mode, but its
    BVH importer still opens files with open(path, 'rU') ("ValueError: invalid mode: 'rU'").
    Drop the flag for that module only (as tests/viewers/blender_import_check.py does)."""
    from io_anim_bvh import import_bvh

    def open_without_u(file, mode="r", *args, **kwargs):
        return builtins.open(file, mode.replace("U", ""), *args, **kwargs)

    import_bvh.open = open_without_u


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(
        prog="blender --python scripts/blender-import.py --",
        description="Import duet's BVH files into Blender at their true size.")
    parser.add_argument("files", nargs="+", help="BVH files, e.g. partner.bvh user.bvh")
    parser.add_argument("--scale", type=float,
                        help="metres per file unit for every file (default: duet inspect's)")
    parser.add_argument("--fps", type=float, help="scene frame rate (default: the files')")
    parser.add_argument("--duet", help="the duet binary (default: $DUET, duet on the PATH, "
                                       "build/apps/duet/duet beside this script)")
    parser.add_argument("--check", action="store_true",
                        help="verify frames and the dancers' extents against duet inspect")
    args = parser.parse_args(argv)
    if args.scale is not None and not (1e-4 <= args.scale <= 1e3):
        parser.error(f"--scale must be between 0.0001 and 1000 metres per file unit, "
                     f"got {args.scale}")
    if args.fps is not None and not (1 <= args.fps <= 1000):
        parser.error(f"--fps must be between 1 and 1000, got {args.fps}")
    return args


def find_duet(given):
    here = os.path.dirname(os.path.abspath(__file__))
    for candidate in (given, os.environ.get("DUET"), shutil.which("duet"),
                      os.path.join(here, "..", "build", "apps", "duet", "duet")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    return None


def inspect(duet, path):
    """duet's own reading of the file: units (metres per unit) and world bounding box."""
    run = subprocess.run([duet, "inspect", "--json", path], capture_output=True, text=True,
                         check=False)
    if run.returncode != 0:
        raise ImportFailed(f"{path}: `duet inspect --json` failed: {run.stderr.strip()}")
    return json.loads(run.stdout)


def read_header(path):
    """(frames, frame time) from the file's MOTION header."""
    frames, frame_time = None, None
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            words = line.split()
            if words[:1] == ["Frames:"]:
                frames = int(words[1])
            elif words[:2] == ["Frame", "Time:"]:
                frame_time = float(words[2])
                break
    if frames is None or not frame_time or frame_time <= 0:
        raise ImportFailed(f"{path}: no 'Frames:' and 'Frame Time:' header: is it a BVH file?")
    return frames, frame_time


def import_bvh(path, metres_per_unit):
    before = set(bpy.data.objects)
    result = bpy.ops.import_anim.bvh(
        filepath=path,
        target='ARMATURE',
        global_scale=metres_per_unit,
        frame_start=1,
        use_fps_scale=False,
        update_scene_fps=False,
        update_scene_duration=False,
        use_cyclic=False,
        rotate_mode='NATIVE',
        axis_forward='-Z',
        axis_up='Y',
    )
    new = [o for o in bpy.data.objects if o not in before and o.type == 'ARMATURE']
    if result != {'FINISHED'} or len(new) != 1:
        raise ImportFailed(f"{path}: Blender's BVH importer returned {result}")
    return new[0]


def extent_in_blender(arm, frames):
    """(min, max) over all frames of the joints' world positions, in the BVH's axes (y up):
    every bone's head, and the tails of leaf bones (the End Sites)."""
    scene = bpy.context.scene
    low, high = [math.inf] * 3, [-math.inf] * 3
    for frame in range(1, frames + 1):
        scene.frame_set(frame)
        for bone in arm.pose.bones:
            points = [bone.head] + ([bone.tail] if not bone.children else [])
            for p in points:
                w = arm.matrix_world @ p
                bvh = (w.x, w.z, -w.y)  # inverse of the import's axis conversion
                low = [min(a, b) for a, b in zip(low, bvh)]
                high = [max(a, b) for a, b in zip(high, bvh)]
    return low, high


def check(path, arm, frames, info):
    failures = []
    action = arm.animation_data.action if arm.animation_data else None
    if action is None:
        return [f"{path}: no animation after import"]
    first, last = action.frame_range
    if (first, last) != (1.0, float(frames)):
        failures.append(f"{path}: keys on frames {first:g}-{last:g}, the file has {frames}")
    low, high = extent_in_blender(arm, frames)
    box = info["bounding_box_m"]
    worst = max(abs(a - b) for a, b in zip(low + high, box["min"] + box["max"]))
    if worst > 0.005:
        def metres(v):
            return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"
        failures.append(f"{path}: Blender shows the dancer within {metres(low)}..{metres(high)} "
                        f"m, duet within {metres(box['min'])}..{metres(box['max'])} m "
                        f"({worst * 1000:.1f} mm apart): wrong scale?")
    print(f"{PREFIX}check {path}: {frames} frames, Blender's extent of the motion is "
          f"{worst * 1000:.2f} mm from duet's (height {high[1] - low[1]:.2f} m)")
    return failures


def main():
    args = parse_args()
    duet = find_duet(args.duet)
    if duet is None and (args.scale is None or args.check):
        raise ImportFailed("cannot find duet to read the files' units: put it on the PATH "
                           "(cmake --install build), pass --duet PATH, or give --scale S")

    # An empty scene (the user's startup file without its objects: no default cube).
    bpy.ops.wm.read_homefile(use_empty=True)
    patch_debian_importer()
    scene = bpy.context.scene

    imported = []
    for path in args.files:
        frames, frame_time = read_header(path)
        info = inspect(duet, path) if duet else None
        scale = args.scale if args.scale is not None else info["metres_per_unit"]
        arm = import_bvh(path, scale)
        how = "--scale" if args.scale is not None else \
            f"duet: {info['units']['source'] or 'units'}"
        print(f"{PREFIX}{path} -> armature '{arm.name}', {frames} frames at "
              f"{1 / frame_time:.6g} fps, {scale:.6g} m per file unit ({how})")
        imported.append((path, arm, frames, frame_time, info))

    rate = args.fps if args.fps else 1 / imported[0][3]
    scene.render.fps = max(1, round(rate))
    scene.render.fps_base = scene.render.fps / rate
    scene.frame_start = 1
    scene.frame_end = max(frames for _, _, frames, _, _ in imported)
    scene.frame_set(1)
    print(f"{PREFIX}scene at {rate:.6g} fps, frames 1-{scene.frame_end}")

    if args.check:
        failures = []
        for path, arm, frames, _, info in imported:
            failures += check(path, arm, frames, info)
        for msg in failures:
            print(PREFIX + "FAIL: " + msg, file=sys.stderr)
        if failures:
            raise ImportFailed(f"{len(failures)} check(s) failed")
        print(f"{PREFIX}check passed")


main()
