#!/usr/bin/env python3
"""Writes a dynamically similar copy of a robot (an MJCF file and its dgmm config) at another size:
every length times s, masses times s^3, torques (kp, force ranges, springs) times s^4, joint
damping times s^4.5, armature times s^5, the contact's impedance width times s and every time
(timestep, contact time constant, gait period, command and settle durations) times sqrt(s), gravity
and friction unchanged (Froude
scaling: the copy walks as the original would, only larger or smaller and slower or faster).
Used to check that dgmm holds no length, mass or time of one robot's size (docs/simulation.md,
"One robot at three sizes").

Usage: scripts/scaled_robot.py --config datasets/robots/hexapod.json --factor 4 -o DIR
Writes DIR/<name>_x<factor>.xml and .json. Refuses (exit 2, one line) a model with meshes, height
fields, includes or slide joints, whose scaling it does not know.
"""
import argparse, json, math, os, sys
import xml.etree.ElementTree as ET

LENGTH_LISTS = ("pos", "size", "fromto")  # every entry a length
REFUSED = ("mesh", "hfield", "include", "tendon")


def scaled(text, factor):
    return " ".join(repr(float(v) * factor) for v in text.split())


def scale_model(root, s, where):
    t = math.sqrt(s)
    for el in root.iter():
        if el.tag in REFUSED:
            raise ValueError(f"{where}: <{el.tag}> is not scaled by this script")
        if el.tag == "joint" and el.get("type") == "slide":
            raise ValueError(f"{where}: slide joint {el.get('name', '(unnamed)')}: its range is a length this "
                             "script does not scale")
        for key in LENGTH_LISTS:
            if key in el.attrib and not (el.tag == "geom" and el.get("type") == "plane" and key == "size"):
                el.set(key, scaled(el.get(key), s))
        factors = {"mass": s ** 3, "diaginertia": s ** 5, "fullinertia": s ** 5, "armature": s ** 5,
                   "damping": s ** 4.5, "stiffness": s ** 4, "frictionloss": s ** 4}
        if el.tag in ("position", "motor", "general", "velocity"):
            factors.update({"kp": s ** 4, "forcerange": s ** 4})  # a position servo's ctrl is an angle
        for key, f in factors.items():
            if key in el.attrib:
                el.set(key, scaled(el.get(key), f))
        if el.tag == "option" and "timestep" in el.attrib:
            el.set("timestep", scaled(el.get("timestep"), t))
    # The contact's time constant (MuJoCo's default 0.02 s) scales with time.
    default = root.find("default")
    if default is None:
        default = ET.SubElement(root, "default")
    geom = default.find("geom")
    if geom is None:
        geom = ET.SubElement(default, "geom")
    ref = geom.get("solref", "0.02 1").split()
    geom.set("solref", f"{float(ref[0]) * t!r} {ref[1]}")
    # The impedance's width (MuJoCo's default 1 mm of penetration) is a length.
    imp = geom.get("solimp", "0.9 0.95 0.001 0.5 2").split()
    imp[2] = repr(float(imp[2]) * s)
    geom.set("solimp", " ".join(imp))
    for el in root.iter("geom"):
        if el is not geom and ("solref" in el.attrib or "solimp" in el.attrib or "margin" in el.attrib):
            raise ValueError(f"{where}: a geom's own solref, solimp or margin is not scaled by this script")


def scale_config(cfg, s):
    t = math.sqrt(s)
    for key in ("timestep_s", "command_duration_s", "settle_duration_s"):
        if key in cfg:
            cfg[key] *= t
    if "placement_half_width_m" in cfg:
        cfg["placement_half_width_m"] *= s
    gait = cfg.get("robot", {}).get("gait", {})
    if "period_s" in gait:
        gait["period_s"] *= t
    for key in ("stride_m", "step_height_m", "stance_height_m"):
        if key in gait:
            gait[key] *= s
    if "terrain" in cfg or "payload" in cfg:
        raise ValueError("a terrain or payload block is not scaled by this script")
    return cfg


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", required=True)
    ap.add_argument("--factor", type=float, required=True)
    ap.add_argument("-o", "--out", required=True)
    a = ap.parse_args()
    try:
        if not a.factor > 0:
            raise ValueError(f"--factor: a positive number expected, got {a.factor}")
        cfg = json.load(open(a.config))
        mjcf = os.path.join(os.path.dirname(a.config), cfg["mjcf_path"])
        tree = ET.parse(mjcf)
        scale_model(tree.getroot(), a.factor, mjcf)
        tree.getroot().insert(0, ET.Comment(f" {os.path.basename(mjcf)} scaled dynamically by {a.factor:g} "
                                            "(scripts/scaled_robot.py) "))
        scale_config(cfg, a.factor)
    except (OSError, ValueError, KeyError, ET.ParseError) as e:
        print(f"scaled_robot.py: error: {a.config}: {e}", file=sys.stderr)
        return 2
    os.makedirs(a.out, exist_ok=True)
    name = f"{os.path.splitext(os.path.basename(mjcf))[0]}_x{a.factor:g}"
    cfg["mjcf_path"] = name + ".xml"
    tree.write(os.path.join(a.out, name + ".xml"))
    json.dump(cfg, open(os.path.join(a.out, name + ".json"), "w"), indent=2)
    print(os.path.join(a.out, name + ".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
