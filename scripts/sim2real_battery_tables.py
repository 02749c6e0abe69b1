"""Markdown tables of scripts/sim2real_battery.py: targets, confusion matrix, every pair."""
from sim2real_battery_draw import FAMILIES, FAMILIES_V1

TARGETS = [  # key, what, target (text), test on the measured value (issue #22's acceptance)
    ("null_clean", "nulls clean (status clean, nothing named)", "100%", lambda r: r >= 1.0),
    ("in_library_correct", "true family named first or in its reported tie (single effects)",
     ">= 90%", lambda r: r >= 0.90),
    ("two_effect_both_found", "two-effect pairs: both families found", ">= 70%",
     lambda r: r >= 0.70),
    ("confident_wrong", "confident wrong first name (inclusion >= 0.8, no tie, no doubt), all pairs",
     "<= 1 in 40", lambda r: r <= 1 / 40),
    ("out_of_library_unexplained", "out-of-library pairs reported unexplained / partly explained",
     "(reported)", lambda r: True),
    ("out_of_library_doubted", "out-of-library pairs unexplained / partly explained with a doubt saying what does not fit",
     ">= 80%", lambda r: r >= 0.80),
    ("value_within_25pct", "knob value within +-25% of the planted one (correctly named effects)",
     ">= 85%", lambda r: r >= 0.85),
]


def _pct(hits_n):
    hits, n = hits_n
    return f"{hits}/{n} ({100 * hits / n:.0f}%)" if n else "no pairs"


def _fmt(v, digits=3):
    return "-" if v is None else f"{v:.{digits}g}" if isinstance(v, float) else str(v)


def targets_table(summary):
    rows = ["| target | required | measured | met |", "|---|---|---|---|"]
    for key, what, target, ok in TARGETS:
        hits, n = summary[key]
        met = "-" if not n else "yes" if ok(hits / n) else "**no**"
        rows.append(f"| {what} | {target} | {_pct(summary[key])} | {met} |")
    g = summary["median_gap_closed"]
    rows.append(f"| median held-out gap closed (pairs with a gap: {summary['gaps_counted']}) | "
                f">= 80% | {'-' if g is None else f'{100 * g:.0f}%'} | "
                f"{'-' if g is None else 'yes' if g >= 0.8 else '**no**'} |")
    first = ", ".join(f"{t:.0f} s" for t in summary["wall_s_first_uncached"]) or "-"
    c = summary["wall_s_cached_median"]
    cmax = summary["wall_s_cached_max"]
    rows.append(f"| wall time of one analysis, signatures cached (median / max) | < 180 s | "
                f"{_fmt(c and round(c))} s / {_fmt(cmax and round(cmax))} s | "
                f"{'-' if cmax is None else 'yes' if cmax < 180 else '**no**'} |")
    rows.append(f"| wall time of an uncached analysis (signatures simulated) | (reported) | {first} | - |")
    part = ", ".join(f"{t:.0f} s" for t in summary.get("wall_s_partially_cached", [])) or "-"
    rows.append(f"| wall time of a partly cached analysis (some signatures simulated) | (reported) | "
                f"{part} | - |")
    if "advised" in summary:
        hits, n = summary["advised_in_library_on_truth"]
        rows.append(f"| advice to record more placements (unexplained pairs): pairs advised; in-library "
                    f"ones pointing at a planted family; nulls; out of library | (reported) | "
                    f"{summary['advised']}; {hits} of {n}; {summary['advised_nulls']}; "
                    f"{summary['advised_out_of_library']} | - |")
    return "\n".join(rows)


def confusion_matrix(results):
    # Families only draw version 2 plants (backlash) get a column only when a pair has them, so
    # version-1 tables keep their layout.
    used = {e["family"] for r in results for e in r.get("effects", [])} | \
        {r["score"]["column"] for r in results if "score" in r}
    families = [f for f in FAMILIES if f in FAMILIES_V1 or f in used]
    cols = families + ["tie", "unexplained", "none"]
    rows = families + ["null", "out_of_library"]
    counts = {r: {c: 0 for c in cols} for r in rows}
    for r in results:
        if "score" not in r or r["kind"] == "two":
            continue
        row = "null" if r["kind"] == "null" else r["effects"][0]["family"]
        col = r["score"]["column"]
        counts[row][col if col in cols else "unexplained"] += 1
    short = {"actuator_gain": "gain", "joint_damping": "damping", "tracker_bias": "trk_bias",
             "tracker_noise": "trk_noise", "heading_drift": "heading", "out_of_library":
             "out of library", "unexplained": "unexpl."}
    head = "| truth \\ named first | " + " | ".join(short.get(c, c) for c in cols) + " | pairs |"
    lines = [head, "|---" * (len(cols) + 2) + "|"]
    for row in rows:
        n = sum(counts[row].values())
        if not n:
            continue
        cells = [f"**{counts[row][c]}**" if c == row or (row == "null" and c == "none")
                 or (row == "out_of_library" and c == "unexplained") else
                 (str(counts[row][c]) if counts[row][c] else ".") for c in cols]
        lines.append(f"| {short.get(row, row)} | " + " | ".join(cells) + f" | {n} |")
    return "\n".join(lines)


def pair_table(results):
    lines = ["| seed | robot | kind | planted | detectability (mean / consistent / spread z) | status | "
             "named (inclusion) | ties | score | value error | gap closed | wall |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        planted = "; ".join(e["what"] for e in r["effects"]) or "nothing (another seed)"
        d = r["detectability"]
        det = f"{_fmt(d['mean_shift_z'], 2)} / {_fmt(d['consistent_z'], 2)} / {_fmt(d['spread_z'], 2)}"
        if "score" not in r:
            lines.append(f"| {r['seed']} | {r['robot']} | {r['kind']} | {planted} | {det} | "
                         f"error: {r.get('error', '')[:80]} | | | | | | {r['analysis_wall_s']:.0f} s |")
            continue
        s = r["score"]
        named = ", ".join(f"{n[0]} ({'n/c' if n[3] is None else f'{100 * n[3]:.0f}%'})"
                          for n in s["named"][:3]) or "none"
        if s.get("drifting"):
            named += "; drifting: " + ", ".join(s["drifting"])
        ties = "; ".join("/".join(t) for t in s["ties"]) or "-"
        verdict = ("clean" if s.get("clean") else "correct" if s.get("correct") else
                   "both" if s.get("both_found") else "one" if s.get("one_found") else
                   "unexplained" if s.get("unexplained_reported") else "wrong")
        if s["confident_wrong"]:
            verdict += ", confident"
        advice = s.get("advice")
        status = s["status"]
        if advice:
            needed, factor = advice["placements_needed"], advice.get("max_factor")
            # Reports before max_factor was written had the default, 16.
            beyond = f"; advice: beyond {16 if factor is None else f'{factor:g}'} times the placements"
            status += (f"; advice: {needed} placements" if needed else beyond) + f" ({advice['knob']})"
        errs = ", ".join("-" if v is None else "other knob" if v["error"] is None
                         else f"{100 * v['error']:+.0f}%" for v in (s.get("values") or {}).values())
        g = s.get("gap_closed")
        lines.append(f"| {r['seed']} | {r['robot']} | {r['kind']} | {planted} | {det} | "
                     f"{status} | {named} | {ties} | {verdict} | {errs or '-'} | "
                     f"{'-' if g is None else f'{100 * g:.0f}%'} | {r['analysis_wall_s']:.0f} s |")
    return "\n".join(lines)


def markdown(results, summary, command, smoke=False):
    fallback = any(r.get("score", {}).get("fallback_mapping") for r in results)
    two = [r for r in results if r["kind"] == "two" and "score" in r]
    parts = [
        f"Generated by `{command}`"
        f"{' (smoke run)' if smoke else ''}: {summary['pairs']} of {len(results)} pairs analysed "
        f"and scored" + ("" if summary["pairs"] == len(results) else
                         f"; the other {len(results) - summary['pairs']} were not analysed "
                         f"(see their rows: stopped or not started at --stop-at)") + ".",
        ("Scored through the fallback mapping of the old `effects` list (no `verdict` in the "
         "reports)." if fallback else ""),
        "**Targets** (issue #9)", targets_table(summary),
        "**Confusion matrix** (single-effect pairs of both robots, nulls and out-of-library "
        "pairs; a column per first-named family, `tie` = first named is another family but tied "
        "with the true one, `unexpl.` = nothing named but a mismatch reported, `none` = clean)",
        confusion_matrix(results),
        f"**Two-effect pairs**: both found in {_pct(summary['two_effect_both_found'])}, at least "
        f"one in {sum(r['score']['one_found'] for r in two)}/{len(two)}.",
        "**Every pair** (detectability: method-free z-scores of the real-vs-sim difference, "
        "about 0 when nothing differs; see above)", pair_table(results),
    ]
    return "\n\n".join(p for p in parts if p) + "\n"
