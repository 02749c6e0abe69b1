#!/usr/bin/env python3
"""A robot that lost a leg: writes the model of a config's robot without one leg, and a config
for it, so the robot can be walked (scripts/walk_table.py) and recorded (dgmm simulate) as it is
now. The leg's body is the one that carries its first joint; it goes with everything below it,
and with the actuators, sensors, contact pairs, equalities and tendons that name anything in it.
Files the model <include>s are written into it (as MuJoCo 2.2 reads them: paths relative to the
main file's folder), and keyframes lose the leg's entries of qpos, qvel and ctrl (a layout like
MuJoCo Menagerie's scene.xml including robot.xml with a home keyframe). Asset folders are made
absolute, so meshes and height fields are found where they were. A named gait pattern becomes
auto (the wave on legs no longer as many on each side); custom phases lose the leg's.

Usage: scripts/drop_leg.py --config datasets/robots/hexapod.json --leg rear_right --out DIR
Writes DIR/<config name>_without_<leg>.{xml,json}; refuses a keyframe with act, mpos or mquat
when the leg has stateful actuators or mocap bodies (their entries are not traced here).
"""
import argparse, json, os, sys
import xml.etree.ElementTree as ET


def fail(message):
    sys.exit(f"drop_leg: {message}")


def inlined(path, main_dir, depth=0):
    """The element tree of `path` with every <include> replaced by the included file's contents."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        fail(f"{path}: {e}")
    if depth > 20:
        fail(f"{path}: <include> nested over 20 deep (a cycle?)")
    for parent in list(root.iter()):
        for i, inc in reversed(list(enumerate(parent))):
            if inc.tag != "include":
                continue
            if not inc.get("file"):
                fail(f"{path}: <include> without a file")
            parent.remove(inc)
            for k, child in enumerate(inlined(os.path.join(main_dir, inc.get("file")), main_dir, depth + 1)):
                parent.insert(i + k, child)
    return root


def joint_type(joint, parents, defaults):
    """A joint's type: its own, else its class's (or the nearest body's childclass) up the defaults."""
    if joint.tag == "freejoint":
        return "free"
    if joint.get("type"):
        return joint.get("type")
    cls, e = joint.get("class"), joint
    while cls is None and e in parents:
        e = parents[e]
        cls = e.get("childclass")
    d = defaults.get(cls or "main")
    while d is not None:
        j = d.find("joint")
        if j is not None and j.get("type"):
            return j.get("type")
        d = parents.get(d) if parents.get(d) is not None and parents[d].tag == "default" else None
    return "hinge"


QPOS, QVEL = {"free": 7, "ball": 4}, {"free": 6, "ball": 3}


def keep_mask(root, parents, gone_elements, tags, size=lambda e: 1):
    """Per entry of a keyframe vector laid out over `tags` elements in model order: kept or not."""
    mask = []
    for e in root.iter():
        if e.tag in tags and (e.tag != "joint" or parents[e].tag == "body"):
            mask += [e not in gone_elements] * size(e)
    return mask


def edit_keyframes(root, parents, gone, path):
    """Keyframes without the entries of the joints and actuators in `gone` (elements)."""
    keys = [k for kf in root.findall("keyframe") for k in kf.findall("key")]
    if not keys:
        return
    defaults = {d.get("class", "main"): d for d in root.iter("default")}
    types = {e: joint_type(e, parents, defaults) for e in root.iter()
             if e.tag in ("joint", "freejoint") and parents[e].tag == "body"}
    joint_tags = ("joint", "freejoint")
    qpos = keep_mask(root, parents, gone, joint_tags, lambda e: QPOS.get(types[e], 1))
    qvel = keep_mask(root, parents, gone, joint_tags, lambda e: QVEL.get(types[e], 1))
    ctrl = [a not in gone for s in root.findall("actuator") for a in s]
    stateful = any(a.get("dyntype") or a.tag in ("cylinder", "muscle", "intvelocity")
                   for s in root.findall("actuator") for a in s if a in gone)
    mocap = any(b.get("mocap") == "true" for b in gone if b.tag == "body")
    for k in keys:
        if (k.get("act") and stateful) or ((k.get("mpos") or k.get("mquat")) and mocap):
            fail(f"{path}: keyframe {k.get('name', '?')}: act, mpos and mquat are not edited here")
        for attr, mask in (("qpos", qpos), ("qvel", qvel), ("ctrl", ctrl)):
            if k.get(attr) is None:
                continue
            values = k.get(attr).split()
            if len(values) != len(mask):
                fail(f"{path}: keyframe {k.get('name', '?')}: {attr} has {len(values)} values, {len(mask)} expected")
            k.set(attr, " ".join(v for v, keep in zip(values, mask) if keep))


def without_leg(mjcf_path, first_joint):
    """The model's element tree without the body carrying `first_joint` and what names its contents."""
    here = os.path.dirname(os.path.abspath(mjcf_path))
    root = inlined(mjcf_path, here)
    parents = {c: p for p in root.iter() for c in p}
    hip = next((j for j in root.iter("joint") if j.get("name") == first_joint), None)
    if hip is None:
        fail(f"{mjcf_path}: no joint named {first_joint}")
    body = parents[hip]
    gone = {e.get("name") for e in body.iter() if e.get("name")}
    naming = [(s, e) for section in ("actuator", "sensor", "contact", "equality", "tendon")
              for s in root.findall(section) for e in s if any(v in gone for v in e.attrib.values())]
    edit_keyframes(root, parents, set(body.iter()) | {e for s, e in naming if s.tag == "actuator"}, mjcf_path)
    parents[body].remove(body)
    for s, e in naming:
        s.remove(e)
    compilers = root.findall("compiler") or [ET.SubElement(root, "compiler")]
    for key in ("meshdir", "texturedir"):  # MuJoCo 2.2 has no assetdir; a later compiler's overrides
        for compiler in [c for c in compilers if c.get(key) is not None] or compilers[:1]:
            compiler.set(key, os.path.join(here, compiler.get(key, "")))
    return ET.ElementTree(root)


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
