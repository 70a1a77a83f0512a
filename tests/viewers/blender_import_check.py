"""Opens the two BVH files `duet follow` wrote in Blender's own BVH importer and checks that the
dancers are where duet says they are.

    blender -b --factory-startup --python-exit-code 1 --python blender_import_check.py -- \
        --user USER.bvh --partner PARTNER.bvh --reference REFERENCE.json [--tolerance-mm 1] \
        [--report REPORT.json]

REFERENCE.json is written by viewer_reference (tests/viewers/viewer_reference.cc): world
positions (metres, BVH axes, y up) of every joint of both dancers at the checked frames, computed
with duet's reader and forward kinematics, plus the contact frames.

Both files are imported into one scene with the importer's settings for a Y-up BVH:
global_scale = the file's metres per unit (duet writes in the source files' units; the reference
gives the scale), axis_forward -Z, axis_up Y (Blender is Z-up: a BVH point
(x, y, z) lands at (x, -z, y)), native Euler orders, one Blender frame per BVH frame
(use_fps_scale off, the scene's rate set from the file's Frame Time). Debian's importer needs
one shim to open files at all (patch_debian_importer). Checked:

- each armature has the file's frame count (keys at frames 1..N) and the scene runs at the
  reference's frame rate;
- at every checked frame, the world-space head of every pose bone equals duet's position of that
  joint within the tolerance (after mapping Blender's axes back to the BVH's);
- the pair is where a salsa couple belongs, read from Blender's positions: both dancers upright
  on the floor (hips 0.6-1.3 m above z = 0, lowest ankle joint below 0.25 m); hips 0.2-2.5 m apart
  horizontally (the range of all 14 captured salsa takes) and within 0.15 m of the couple's
  spacing in the capture at the follower's template frame (alignment reproduces it; foot lock
  may shift the partner by up to 0.15 m); at contact frames the held hands (wrist joints) as far
  apart as in the capture at the template frame, within 0.15 m (the contact IK aims at the
  captured grip; how exactly it holds it is measured by `duet eval`, not here: this checks that
  the two files share one world frame and hold the couple as captured).

Exits non-zero (via --python-exit-code) with a message per failed check.
"""
import argparse
import json
import math
import sys

import builtins

import bpy


def patch_debian_importer():
    """Debian 12's blender 3.4.1 runs on Python 3.11, which removed the "U" file mode, but its
    BVH importer still opens files with open(path, 'rU') ("ValueError: invalid mode: 'rU'": the
    importer fails on every file). Drop the flag for that module only; the importer's parsing and
    conversion are untouched."""
    from io_anim_bvh import import_bvh

    def open_without_u(file, mode="r", *args, **kwargs):
        return builtins.open(file, mode.replace("U", ""), *args, **kwargs)

    import_bvh.open = open_without_u


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender_import_check.py")
    parser.add_argument("--user", required=True)
    parser.add_argument("--partner", required=True)
    parser.add_argument("--reference", required=True)
    parser.add_argument("--tolerance-mm", type=float, default=1.0)
    parser.add_argument("--report")
    return parser.parse_args(argv)


def import_bvh(path, metres_per_unit):
    before = set(bpy.data.objects)
    result = bpy.ops.import_anim.bvh(
        filepath=path,
        target='ARMATURE',
        global_scale=metres_per_unit,
        frame_start=1,
        use_fps_scale=False,
        update_scene_fps=True,
        update_scene_duration=True,
        use_cyclic=False,
        rotate_mode='NATIVE',
        axis_forward='-Z',
        axis_up='Y',
    )
    if result != {'FINISHED'}:
        raise SystemExit(f"{path}: import_anim.bvh returned {result}")
    new = [o for o in bpy.data.objects if o not in before and o.type == 'ARMATURE']
    if len(new) != 1:
        raise SystemExit(f"{path}: expected one new armature, got {len(new)}")
    return new[0]


def to_bvh_axes(v):
    # Inverse of the importer's axis conversion (forward -Z, up Y): Blender (x, y, z) is BVH
    # (x, z, -y).
    return (v.x, v.z, -v.y)


def main():
    args = parse_args()
    with open(args.reference) as f:
        ref = json.load(f)
    failures = []

    # An empty scene: no default cube, camera or light (--factory-startup still has them).
    bpy.ops.wm.read_factory_settings(use_empty=True)
    patch_debian_importer()
    scene = bpy.context.scene
    scale = ref["metres_per_unit"]
    arms = {"user": import_bvh(args.user, scale["user"]),
            "partner": import_bvh(args.partner, scale["partner"])}

    fps = scene.render.fps / scene.render.fps_base
    if abs(fps - ref["fps"]) > 1e-6:
        failures.append(f"scene frame rate {fps} after import, reference {ref['fps']}")
    for who, arm in arms.items():
        action = arm.animation_data.action if arm.animation_data else None
        if action is None:
            failures.append(f"{who}: no action after import")
            continue
        counts = {len(c.keyframe_points) for c in action.fcurves}
        first, last = action.frame_range
        if counts != {ref["frames"]} or (first, last) != (1.0, float(ref["frames"])):
            failures.append(f"{who}: keys per curve {sorted(counts)}, frame range "
                            f"{first:g}-{last:g}; reference {ref['frames']} frames")
        names = set(arm.pose.bones.keys())
        missing = [n for n in ref["joints"][who] if n not in names]
        if missing:
            failures.append(f"{who}: bones missing in Blender: {missing}")

    tol = args.tolerance_mm / 1000.0
    max_diff = {"user": 0.0, "partner": 0.0}
    worst = {"user": None, "partner": None}
    positions = {"user": [], "partner": []}  # per checked frame: {joint: (x, y, z)} in BVH axes
    for i, frame in enumerate(ref["frames_checked"]):
        scene.frame_set(frame + 1)  # BVH frame 0 is Blender frame 1
        for who, arm in arms.items():
            world = {}
            for k, name in enumerate(ref["joints"][who]):
                bone = arm.pose.bones.get(name)
                if bone is None:
                    continue
                p = to_bvh_axes(arm.matrix_world @ bone.head)
                world[name] = p
                d = math.dist(p, ref[who][i][k])
                if d > max_diff[who]:
                    max_diff[who] = d
                    worst[who] = (frame, name)
            positions[who].append(world)
    for who in arms:
        if max_diff[who] > tol:
            failures.append(f"{who}: a joint is {max_diff[who] * 1000:.3f} mm from duet's position "
                            f"(frame {worst[who][0]}, {worst[who][1]}); tolerance "
                            f"{args.tolerance_mm} mm")

    # Where the dancers belong (Blender's own positions, BVH axes: y up).
    roles = ref["roles"]
    min_hips_dist, max_hips_dist, max_hand_dist, max_spacing_diff = math.inf, 0.0, 0.0, 0.0
    for i, frame in enumerate(ref["frames_checked"]):
        u, p = positions["user"][i], positions["partner"][i]
        for who, pos in (("user", u), ("partner", p)):
            r = roles[who]
            hips_y = pos[r["hips"]][1]
            foot_y = min(pos[r[j]][1] for j in ("left_ankle", "right_ankle"))
            if not 0.6 <= hips_y <= 1.3 or foot_y > 0.25:
                failures.append(f"{who} at frame {frame}: hips {hips_y:.3f} m and lowest ankle "
                                f"{foot_y:.3f} m above the floor (want 0.6-1.3 m and < 0.25 m)")
        hu, hp = u[roles["user"]["hips"]], p[roles["partner"]["hips"]]
        d = math.hypot(hu[0] - hp[0], hu[2] - hp[2])
        min_hips_dist, max_hips_dist = min(min_hips_dist, d), max(max_hips_dist, d)
        captured = ref["captured_hips_distance_m"][i]
        max_spacing_diff = max(max_spacing_diff, abs(d - captured))
        if not 0.2 <= d <= 2.5 or abs(d - captured) > 0.15:
            failures.append(f"frame {frame}: hips {d:.3f} m apart horizontally, in the capture "
                            f"{captured:.3f} m (want 0.2-2.5 m and within 0.15 m of the capture)")
    for c in ref["contacts"]:
        i = ref["frames_checked"].index(c["frame"])
        d = math.dist(positions["user"][i][c["user_joint"]],
                      positions["partner"][i][c["partner_joint"]])
        max_hand_dist = max(max_hand_dist, abs(d - c["captured_distance_m"]))
        if abs(d - c["captured_distance_m"]) > 0.15:
            failures.append(f"contact frame {c['frame']} ({c['pair']}): user {c['user_joint']} and "
                            f"partner {c['partner_joint']} {d:.3f} m apart, in the capture "
                            f"{c['captured_distance_m']:.3f} m (want within 0.15 m)")

    report = {
        "viewer": f"Blender {bpy.app.version_string}",
        "frames_checked": len(ref["frames_checked"]),
        "contact_frames": len(ref["contacts"]),
        "max_diff_mm": {k: round(v * 1000, 4) for k, v in max_diff.items()},
        "hips_distance_m": [round(min_hips_dist, 3), round(max_hips_dist, 3)],
        "max_hips_distance_vs_capture_m": round(max_spacing_diff, 4),
        "max_contact_hand_vs_capture_m": round(max_hand_dist, 4),
        "fps": fps,
        "failures": failures,
    }
    print("blender_import_check: " + json.dumps(report))
    if args.report:
        with open(args.report, "w") as f:
            json.dump(report, f, indent=2)
    if failures:
        for msg in failures[:20]:
            print("blender_import_check: FAIL: " + msg, file=sys.stderr)
        sys.exit(1)


main()
