#!/usr/bin/env python3
"""A robot that lost a leg: writes the model of a config's robot without one leg, and a config
for it, so the robot can be walked (scripts/walk_table.py) and recorded (dgmm simulate) as it is
now. The leg's body is the one that carries its first joint; it goes with everything below it,
and with the actuators, sensors, contact pairs, equalities and tendons that name anything in it.
Asset folders are made absolute, so meshes and height fields are found where they were. A
named gait pattern becomes auto (the wave on legs no longer as many on each side); custom phases
lose the leg's.

Usage: scripts/drop_leg.py --config datasets/robots/hexapod.json --leg rear_right --out DIR
Writes DIR/<config name>_without_<leg>.{xml,json}; refuses a model with <include> or <keyframe>
(their contents would have to be edited too).
"""
import argparse, json, os, sys
import xml.etree.ElementTree as ET


def fail(message):
    sys.exit(f"drop_leg: {message}")


def without_leg(mjcf_path, first_joint):
    """The model's element tree without the body carrying `first_joint` and what names its contents."""
    try:
        tree = ET.parse(mjcf_path)
    except (OSError, ET.ParseError) as e:
        fail(f"{mjcf_path}: {e}")
    root = tree.getroot()
    for tag in ("include", "keyframe"):
        if root.find(tag) is not None:
            fail(f"{mjcf_path}: a model with <{tag}> is not edited here")
    parents = {c: p for p in root.iter() for c in p}
    hip = next((j for j in root.iter("joint") if j.get("name") == first_joint), None)
    if hip is None:
        fail(f"{mjcf_path}: no joint named {first_joint}")
    body = parents[hip]
    gone = {e.get("name") for e in body.iter() if e.get("name")}
    parents[body].remove(body)
    for section in ("actuator", "sensor", "contact", "equality", "tendon"):
        for s in root.findall(section):
            for e in list(s):
                if any(v in gone for v in e.attrib.values()):
                    s.remove(e)
    compiler = root.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(root, "compiler")
    here = os.path.dirname(os.path.abspath(mjcf_path))
    for key in ("meshdir", "texturedir"):  # MuJoCo 2.2 has no assetdir
        compiler.set(key, os.path.join(here, compiler.get(key, "")))
    return tree


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", required=True)
    ap.add_argument("--leg", required=True, help="the leg's name in the config's robot block")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    try:
        cfg = json.load(open(a.config))
    except (OSError, ValueError) as e:
        fail(f"{a.config}: {e}")
    if not isinstance(cfg, dict) or "mjcf_path" not in cfg:
        fail(f"{a.config}: mjcf_path expected")
    legs = cfg.get("robot", {}).get("legs", [])
    leg = next((l for l in legs if l.get("name") == a.leg), None)
    if leg is None:
        fail(f"{a.config}: no leg named {a.leg} (legs: {', '.join(l.get('name', '?') for l in legs) or 'none'})")
    here = os.path.dirname(os.path.abspath(a.config))
    tree = without_leg(os.path.join(here, cfg["mjcf_path"]), leg["joints"][0])
    for rec in cfg["robot"].get("controller", {}).get("recordings", []):  # a replayed controller's files
        rec["file"] = os.path.join(here, rec["file"])
    os.makedirs(a.out, exist_ok=True)
    stem = os.path.join(a.out, os.path.splitext(os.path.basename(a.config))[0] + "_without_" + a.leg)
    tree.write(stem + ".xml")
    cfg["mjcf_path"] = os.path.abspath(stem + ".xml")
    cfg["robot"]["legs"] = [l for l in legs if l is not leg]
    gait = cfg["robot"].get("gait", {})
    if gait.get("pattern") == "custom":  # the lost leg's phase goes with it
        del gait["phases"][legs.index(leg)]
    elif gait.get("pattern", "auto") != "auto":
        print(f"drop_leg: gait pattern {gait['pattern']} replaced by auto (the wave for legs uneven on the sides)")
        gait["pattern"] = "auto"
    with open(stem + ".json", "w") as f:
        json.dump(cfg, f, indent=2)
    print(stem + ".json")


if __name__ == "__main__":
    main()
