"""Scoring of report.json verdicts against the concealed truth for scripts/sim2real_battery.py.

The contract is the `verdict` object of docs/sim2real.md ("report.json verdict"). Reports written
before it existed (a top-level `effects` list) are mapped onto families by OLD_EFFECT_FAMILY so
the battery runs end to end on either.
"""
import statistics

CONFIDENT = 0.8   # issue #9: "confident wrong" = inclusion >= 80%, no tie reported
VALUE_TOL = 0.25  # issue #9: knob value within +-25% of the planted one

# Fallback for reports without a verdict: the old hand-written effect library.
OLD_EFFECT_FAMILY = {
    "slope_slip": "friction", "slope_traction": "friction", "stride_loss": "actuator_gain",
    "payload_offset": "payload", "actuator_asymmetry": "actuator_gain", "latency": "latency",
    "compliance": "contact", "bias": "tracker_bias", "noise": "tracker_noise",
}

# Words a reported knob name must contain to be the planted knob (knob names are the method's
# own, found from the model; only the physical quantity is compared). A weak leg must be named by
# its index ("leg3"), a weak side by "left"/"right".
KNOB_WORDS = {
    "friction.sliding": ["slid"], "floor.solref.timeconst": ["time"],
    "floor.solref.dampratio": ["damp"], "masses.scale": ["mass"], "payload.mass_kg": ["mass"],
    "actuators.kp_nm_per_rad": ["kp"], "actuators.joint_damping_nms_per_rad": ["damp"],
    "actuators.latency_s": ["laten", "delay"], "floor.solimp.dmax": ["dmax"],
    "actuators.backlash_rad": ["backlash"], "tracker.noise_scale": ["noise"],
}


def verdict_of(report):
    """The report's verdict, or one built from an old report's effects list."""
    if isinstance(report.get("verdict"), dict):
        return report["verdict"], False
    named = [{"family": OLD_EFFECT_FAMILY.get(e.get("effect"), e.get("effect")), "knob": None,
              "value": None, "inclusion": e.get("inclusion_probability"), "tie_group": None}
             for e in report.get("effects", [])]
    unexplained = bool(report.get("unexplained"))
    located = report.get("conditional_flagged_regions", 0) > 0
    status = ("clean" if not located and not named else "unexplained" if not named
              else "partly_explained" if unexplained else "explained")
    return {"status": status, "named": named, "ties": [],
            "unexplained": {"present": unexplained, "structured_in": []},
            "gap_closed": report.get("gap_closed")}, True


def tie_families(verdict, entry):
    """Families reported as indistinguishable from `entry` (its own family included)."""
    fams = {entry.get("family")}
    g = entry.get("tie_group")
    ties = verdict.get("ties") or []
    if isinstance(g, int) and 0 <= g < len(ties):
        fams |= set(ties[g].get("families", []))
    return fams


def found_families(verdict):
    fams = set()
    for n in verdict.get("named") or []:
        fams |= tie_families(verdict, n)
    return fams


def knob_matches(truth_knob, named_knob):
    if truth_knob is None or named_knob is None:
        return False
    named = named_knob.lower().replace(" ", "").replace("_", "")
    if truth_knob.startswith("actuators.leg_gain["):
        which = truth_knob[len("actuators.leg_gain["):-1]
        return (f"leg{which}" in named) if which.isdigit() else which in named
    if truth_knob in KNOB_WORDS:
        return any(w in named for w in KNOB_WORDS[truth_knob])
    if truth_knob.startswith("imu") or truth_knob.startswith("tracker"):
        return True  # measurement effects: one knob per family
    return False


def value_error(effect, verdict):
    """Relative error of the named value of the planted knob, or None when the family is not
    named with a value; error None when only other knobs of the family are named."""
    entries = [n for n in verdict.get("named") or []
               if n.get("family") == effect["family"] and n.get("value") is not None]
    if not entries:
        return None
    for n in entries:
        if not knob_matches(effect["knob"], n.get("knob")):
            continue
        planted, got = effect["value"], float(n["value"])
        if effect["family"] in ("imu_bias", "tracker_bias"):  # "largest offset": magnitude
            planted, got = abs(planted), abs(got)
        return {"error": (got - planted) / abs(planted), "reported": got, "knob": n.get("knob")}
    return {"error": None, "reported": entries[0].get("value"), "knob": entries[0].get("knob"),
            "why": "another knob of the family"}


def column_of(verdict, truth_families):
    """Confusion-matrix column: the first named family, tie, unexplained or none."""
    named = verdict.get("named") or []
    if not named:
        return "unexplained" if verdict.get("status") in ("unexplained", "partly_explained") \
            or (verdict.get("unexplained") or {}).get("present") else "none"
    first = named[0]
    if first.get("family") not in truth_families and truth_families & tie_families(verdict, first):
        return "tie"
    return first.get("family")


def score_pair(pair, report):
    """Scores of one pair (dict) given its truth `pair` and the parsed report.json."""
    verdict, fallback = verdict_of(report)
    truth = {e["family"] for e in pair["effects"] if e["family"] != "out_of_library"}
    named = verdict.get("named") or []
    first = named[0] if named else None
    s = {"status": verdict.get("status"), "fallback_mapping": fallback,
         "named": [[n.get("family"), n.get("knob"), n.get("value"), n.get("inclusion"),
                    n.get("tie_group")] for n in named],
         "ties": [t.get("families") for t in verdict.get("ties") or []],
         "structured_in": (verdict.get("unexplained") or {}).get("structured_in"),
         "drifting": [d.get("family") for d in verdict.get("drifting") or []],
         "gap_closed": verdict.get("gap_closed"), "column": column_of(verdict, truth)}
    kind = pair["kind"]
    if kind == "null":
        s["clean"] = verdict.get("status") == "clean" and not named
    elif kind == "single":
        s["correct"] = first is not None and bool(truth & tie_families(verdict, first))
    elif kind == "two":
        s["both_found"] = truth <= found_families(verdict)
        s["one_found"] = bool(truth & found_families(verdict))
    else:
        s["unexplained_reported"] = verdict.get("status") in ("unexplained", "partly_explained") \
            or bool((verdict.get("unexplained") or {}).get("present"))
        # Issue #22: unexplained or partly explained with a doubt (or located structure) that says
        # what does not fit.
        s["doubt_reported"] = verdict.get("status") in ("unexplained", "partly_explained") and bool(
            verdict.get("doubts") or (verdict.get("unexplained") or {}).get("structured_in"))
    s["doubts"] = verdict.get("doubts") or []
    # Stage 8's advice to record more placements (report.json more_data; null when not advised):
    # whether it points at a planted family is scored, not targeted.
    more = report.get("more_data")
    s["advice"] = None if not more else {
        "knob": more.get("knob"), "family": more.get("family"), "reason": more.get("reason"),
        "placements_needed": more.get("placements_needed"),
        "max_factor": more.get("max_factor"), "on_truth": more.get("family") in truth}
    inclusion = first.get("inclusion") if first else None
    # A stated doubt (issue #22: a value pinned or impossible, mismatch left after the correction)
    # makes an answer not confident.
    s["confident_wrong"] = bool(first is not None and not truth & tie_families(verdict, first)
                                and inclusion is not None and inclusion >= CONFIDENT
                                and first.get("tie_group") is None and not verdict.get("doubts"))
    if kind in ("single", "two"):
        s["values"] = {}
        for e in pair["effects"]:
            if e["family"] in found_families(verdict):
                s["values"][e["family"]] = value_error(e, verdict)
    return s


def _rate(hits):
    hits = list(hits)
    return (sum(hits), len(hits))


def summarize(results):
    """Headline numbers over scored pairs: each a (hits, n) count or a median."""
    by = lambda k: [r for r in results if r["kind"] == k and "score" in r]
    nulls, singles, twos, ool = by("null"), by("single"), by("two"), by("out_of_library")
    scored = [r for r in results if "score" in r]
    # Knob values of the correctly named effects (a family found only through a tie, with no
    # value of its own, counts as a miss).
    values = [v for r in singles if r["score"]["correct"]
              for v in (r["score"].get("values") or {}).values()] + \
             [v for r in twos for v in (r["score"].get("values") or {}).values()]
    gaps = [r["score"]["gap_closed"] for r in scored
            if r["kind"] != "null" and r["score"].get("gap_closed") is not None]
    times = [r["analysis_wall_s"] for r in scored if r.get("analysis_wall_s") is not None]
    # The target is "one analysis once signatures are cached": an analysis counts as cached when
    # its signature stage simulated nothing (report: knob_analysis.signature_simulations == 0;
    # refinement may still simulate, and its time counts). Reports written before that field
    # existed: cached when it took as many runs from the cache as the most any analysis of that
    # robot took in the run (every signature), uncached when it took none, else partial.
    full = {}
    for r in scored:
        if r.get("from_cache") is not None:
            full[r["robot"]] = max(full.get(r["robot"], 0), r["from_cache"])
    def cache_state(r):
        if r.get("signature_simulations") is not None:
            if r["signature_simulations"] == 0:
                return "cached"
            return "uncached" if r.get("from_cache") == 0 else "partial"
        if r.get("from_cache") is None:
            return "uncached" if r.get("first_of_robot") else "cached"
        if r["from_cache"] == 0:
            return "uncached"
        return "cached" if r["from_cache"] >= full[r["robot"]] else "partial"
    first = [r["analysis_wall_s"] for r in scored if cache_state(r) == "uncached"]
    cached = [r["analysis_wall_s"] for r in scored if cache_state(r) == "cached"]
    partial = [r["analysis_wall_s"] for r in scored if cache_state(r) == "partial"]
    advised = [r for r in scored if r["score"].get("advice")]
    return {
        "pairs": len(scored),
        "advised": len(advised),
        "advised_in_library_on_truth": _rate(r["score"]["advice"]["on_truth"] for r in advised
                                             if r["kind"] in ("single", "two")),
        "advised_nulls": sum(r["kind"] == "null" for r in advised),
        "advised_out_of_library": sum(r["kind"] == "out_of_library" for r in advised),
        "null_clean": _rate(r["score"]["clean"] for r in nulls),
        "in_library_correct": _rate(r["score"]["correct"] for r in singles),
        "two_effect_both_found": _rate(r["score"]["both_found"] for r in twos),
        "confident_wrong": _rate(r["score"]["confident_wrong"] for r in scored),
        "out_of_library_unexplained": _rate(r["score"]["unexplained_reported"] for r in ool),
        "out_of_library_doubted": _rate(r["score"].get("doubt_reported", False) for r in ool),
        "value_within_25pct": _rate(v is not None and v["error"] is not None
                                    and abs(v["error"]) <= VALUE_TOL for v in values),
        "median_gap_closed": statistics.median(gaps) if gaps else None,
        "gaps_counted": len(gaps),
        "wall_s_first_uncached": first,
        "wall_s_partially_cached": partial,
        "wall_s_cached_median": statistics.median(cached) if cached else None,
        "wall_s_cached_max": max(cached) if cached else None,
        "wall_s_all_median": statistics.median(times) if times else None,
    }
