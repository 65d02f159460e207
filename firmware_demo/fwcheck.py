#!/usr/bin/python3
"""fwcheck.py - run the firmware demo on the host and under QEMU, and report
flash, RAM and stack per target (the last step of "make firmware").

    fwcheck.py --build build/fw --targets "m4f m7" --machines "mps2-an386 mps2-an500"

Exit status 0 when every run passed, 1 otherwise.  Writes
build/fw/report.txt (what is printed) and build/fw/report.json.

Stack: "static" is the deepest call chain of the library (and of the demo's
main) from the compilers' -fcallgraph-info=su dumps (-fstack-usage frame
sizes, summed along the call graph); calls into newlib's libm/libc and
libgcc are not in those dumps and are listed separately.  "measured" is the
demo's own gauge (the stack is painted, the deepest overwritten word found),
which includes them.
"""
import argparse
import json
import os
import re
import subprocess
import sys

# Entry points whose worst stack depth is reported.
ROOTS = ["pm_model_apply", "pm_model_invert", "pm_model_invert_near", "pm_model_track",
         "pm_model_apply_f", "pm_model_invert_f", "pm_model_invert_near_f", "pm_model_track_f",
         "pm_fit_add", "pm_fit_solve", "pm_fit_run", "main"]


def run(cmd, out_path, timeout):
    """Run cmd, save its output, return (exit code, output)."""
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           timeout=timeout)
        text, rc = p.stdout.decode(errors="replace"), p.returncode
    except subprocess.TimeoutExpired as e:
        text = (e.stdout or b"").decode(errors="replace") + "\n(timed out)\n"
        rc = 124
    with open(out_path, "w") as f:
        f.write(text)
    return rc, text


def map_breakdown(map_path):
    """Flash (text, rodata, data init) and RAM (data, bss) per component,
    from a GNU ld map file."""
    comp = {}
    with open(map_path) as f:
        lines = f.read().split("\n")
    try:
        start = lines.index("Linker script and memory map")
    except ValueError:
        start = 0
    sec_re = re.compile(r"^ (\.[\w.$]+|COMMON)\s*$")
    full_re = re.compile(r"^ (\.[\w.$]+|COMMON)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
    cont_re = re.compile(r"^\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
    pending = None
    for line in lines[start:]:
        m = full_re.match(line)
        if m:
            sec, size, obj = m.group(1), int(m.group(3), 16), m.group(4)
        else:
            m = sec_re.match(line)
            if m:
                pending = m.group(1)
                continue
            m = cont_re.match(line)
            if not (m and pending):
                pending = None
                continue
            sec, size, obj = pending, int(m.group(2), 16), m.group(3)
            pending = None
        if size == 0:
            continue
        if "/core/" in obj:
            name = "pm core"
        elif re.search(r"lib(m|c|g|gcc|rdimon|nosys)(_nano)?\.a", obj):
            name = re.search(r"(lib\w+)\.a", obj).group(1)
        elif obj.endswith(".o"):
            name = os.path.basename(obj)
        else:
            name = "other"
        c = comp.setdefault(name, {"flash": 0, "ram": 0})
        if sec.startswith((".text", ".rodata", ".ARM", ".vectors", ".init", ".fini")):
            c["flash"] += size
        elif sec.startswith(".data"):
            c["flash"] += size
            c["ram"] += size
        elif sec.startswith(".bss") or sec == "COMMON":
            c["ram"] += size
    return comp


def parse_ci(paths):
    """Merge -fcallgraph-info=su dumps: frame size per node, edges."""
    frame, label, edges = {}, {}, {}
    node_re = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
    edge_re = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
    for p in paths:
        with open(p) as f:
            for line in f:
                m = node_re.search(line)
                if m:
                    title, lab = m.group(1), m.group(2)
                    s = re.search(r"(\d+) bytes \((static|dynamic[^)]*)\)", lab)
                    if s:
                        frame[title] = int(s.group(1))
                        label[title] = s.group(2)
                    continue
                m = edge_re.search(line)
                if m:
                    edges.setdefault(m.group(1), set()).add(m.group(2))
    return frame, label, edges


def worst_depth(root, frame, edges):
    """Deepest stack along the call graph from root: (bytes, path, external
    leaves reached, recursion found)."""
    memo, external, state = {}, set(), {"recursive": False}

    def go(n, onpath):
        if n not in frame:
            external.add(n)
            return 0, []
        if n in onpath:
            state["recursive"] = True
            return 0, []
        if n in memo:
            return memo[n]
        best, bpath = 0, []
        for t in sorted(edges.get(n, ())):
            d, path = go(t, onpath | {n})
            if d > best:
                best, bpath = d, path
        memo[n] = (frame[n] + best, [n] + bpath)
        return memo[n]

    if root not in frame:
        return None
    d, path = go(root, frozenset())
    return d, path, sorted(external), state["recursive"]


_demangled = {}


def short(name):
    """A readable function name: demangled, without arguments, namespaces,
    template arguments or GCC's clone suffixes."""
    base = name.split(":")[-1]
    base = re.sub(r"\.(part|constprop|isra)\.\d+$", "", base)
    if base.startswith("_Z") and base not in _demangled:
        try:
            out = subprocess.run(["c++filt", base], stdout=subprocess.PIPE).stdout.decode()
            _demangled[base] = out.strip()
        except OSError:
            _demangled[base] = base
    d = _demangled.get(base, base)
    d = d.replace("(anonymous namespace)::", "").replace("pm::detail::", "")
    # drop the argument list and template arguments
    depth, outname = 0, ""
    for ch in d:
        if ch in "(<":
            depth += 1
        elif ch in ")>":
            depth -= 1
        elif depth == 0:
            outname += ch
    outname = outname.split()[-1] if outname.split() else base
    return outname


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build/fw")
    ap.add_argument("--targets", default="m4f m7")
    ap.add_argument("--machines", default="mps2-an386 mps2-an500")
    ap.add_argument("--qemu", default="qemu-system-arm")
    ap.add_argument("--size", default="arm-none-eabi-size")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--coreof", default="", help="T=U,...: target T uses U's core objects")
    a = ap.parse_args()
    a.coreof = dict(x.strip().split("=") for x in a.coreof.replace(",", " ").split() if "=" in x)
    B = a.build
    targets, machines = a.targets.split(), a.machines.split()
    report, out = {"targets": {}}, []
    ok = True

    def say(s=""):
        out.append(s)
        print(s)

    rc, text = run([os.path.join(B, "host", "demo")], os.path.join(B, "host", "demo.out"),
                   a.timeout)
    passed = rc == 0 and "RESULT: PASS" in text
    ok &= passed
    say("== host (reference build): %s" % ("PASS" if passed else "FAIL, exit %d" % rc))
    if not passed:
        say(text)
    for t, mach in zip(targets, machines):
        elf = os.path.join(B, t, "demo.elf")
        cmd = [a.qemu, "-M", mach, "-nographic", "-semihosting",
               "-icount", "shift=0,align=off,sleep=off", "-kernel", elf]
        rc, text = run(cmd, os.path.join(B, t, "demo.out"), a.timeout)
        passed = rc == 0 and "RESULT: PASS" in text
        ok &= passed
        say("== %s (qemu-system-arm -M %s): %s" % (t, mach, "PASS" if passed
                                                    else "FAIL, exit %d" % rc))
        say("   " + " ".join(cmd))
        for line in text.strip().split("\n"):
            say("   | " + line)
        info = {"machine": mach, "pass": passed, "exit": rc}

        # sizes: the whole image, then the parts
        sz = subprocess.run([a.size, elf], stdout=subprocess.PIPE).stdout.decode().split("\n")
        text_b, data_b, bss_b = [int(x) for x in sz[1].split()[:3]]
        info["elf"] = {"text": text_b, "data": data_b, "bss": bss_b,
                       "flash": text_b + data_b, "ram": data_b + bss_b}
        comp = map_breakdown(os.path.join(B, t, "demo.map"))
        info["components"] = comp
        m = re.search(r"stack: tracking (\d+) bytes, refit (\d+) bytes", text)
        if m:
            info["stack_measured"] = {"tracking": int(m.group(1)), "refit": int(m.group(2))}
        m = re.search(r"sizeof: (.*)", text)
        if m:
            info["sizeof"] = {k: int(v) for k, v in
                              re.findall(r"(pm_\w+) (\d+)", m.group(1))}
        for name in ("pm_model_apply", "pm_model_invert_near", "pm_model_track",
                     "pm_model_apply_f", "pm_model_invert_near_f", "pm_model_track_f",
                     "pm_fit_add", "pm_fit_solve",
                     r"pm_fit_run \(whole\)"):
            m = re.search(name + r"\s+(\d+) instructions mean,\s+(\d+) max", text)
            if m:
                info.setdefault("instructions", {})[name.replace("\\", "")] = {
                    "mean": int(m.group(1)), "max": int(m.group(2))}

        # static stack analysis
        coredir = os.path.join(B, a.coreof.get(t, t), "core")
        cis = [os.path.join(coredir, f) for f in sorted(os.listdir(coredir)) if f.endswith(".ci")]
        cis += [os.path.join(B, t, f) for f in ("demo.ci", "platform_cm.ci")
                if os.path.exists(os.path.join(B, t, f))]
        frame, label, edges = parse_ci(cis)
        dyn = sorted(short(n) for n, l in label.items() if l != "static")
        st = {}
        for r in ROOTS:
            w = worst_depth(r, frame, edges)
            if w:
                d, path, ext, rec = w
                st[r] = {"bytes": d, "path": [short(p) for p in path], "external": ext,
                         "recursive": rec}
        info["stack_static"] = st
        info["stack_dynamic_frames"] = dyn
        report["targets"][t] = info

        say("   flash %d B, RAM %d B (data %d + bss %d), stack region 64 KB" %
            (text_b + data_b, data_b + bss_b, data_b, bss_b))
        say("   %-16s %10s %10s" % ("component", "flash B", "RAM B"))
        for name in sorted(comp, key=lambda n: -comp[n]["flash"] - comp[n]["ram"]):
            say("   %-16s %10d %10d" % (name, comp[name]["flash"], comp[name]["ram"]))
        say("   stack, static analysis (library frames; libm/libgcc calls not included):")
        for r in ROOTS:
            if r in st:
                e = st[r]
                say("     %-22s %6d B  via %s%s" % (
                    r, e["bytes"], " > ".join(e["path"][:6]) + (" ..." if len(e["path"]) > 6 else ""),
                    "  RECURSIVE" if e["recursive"] else ""))
        ext = sorted(set(x for r in st.values() for x in r["external"]))
        say("     calls out to: %s" % " ".join(ext))
        if dyn:
            say("     frames of dynamic size: %s" % " ".join(dyn))
        if "stack_measured" in info:
            sm = info["stack_measured"]
            say("   stack, measured (painted, includes libm/libgcc): tracking %d B, refit %d B"
                % (sm["tracking"], sm["refit"]))

    say()
    say("firmware: %s" % ("all runs PASS" if ok else "FAIL"))
    with open(os.path.join(B, "report.txt"), "w") as f:
        f.write("\n".join(out) + "\n")
    with open(os.path.join(B, "report.json"), "w") as f:
        json.dump(report, f, indent=1, sort_keys=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
