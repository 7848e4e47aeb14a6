#!/usr/bin/env python3
"""The layout's rules (docs/architecture.md), checked on the sources and the
compiled objects:

1. a folder of src/ (and a backend) includes headers only from its own
   folder and the layers below it, internal headers ("util/json.h") and
   public ones ("beamsim/scene.h", each public header belonging to the layer
   that implements it) alike; peers (figures, video) do not include each
   other;
2. no circle of calls between files: the graph "file A calls a function or
   reads an object defined in file B", read off the library's object files
   with nm, has no cycle;
3. no folder of the library holds more than 25 .c files;
4. header guards follow one rule: BSIM_<NAME>_H for a public header,
   BSIM_<FOLDER>_<NAME>_H for the others;
5. every function a public header declares is defined in that header's
   layer, so that a header is one layer's API;
6. beamsim/beamsim.h includes every public header;
7. every definition struct of the public API (bsim_*_def, bsim_*_config)
   has its default function, named bsim_<struct>_default;
8. no file of src/, include/ or bindings/ but the registry's names a
   backend: for every folder NAME of backends/, neither its table
   bsim_backend_NAME nor NAME as a word (a backend's name in a string, a
   default, an example in a help text or a comment) outside a path
   ("configs/NAME/") or a longer name ("NAME-gate"); a comment may still
   speak of "the NAME backend" to state a fact about that backend. The rest
   of the program reaches a backend through the registry, by the name it
   was given or in a loop over the list;
9. every global symbol the library's objects define carries the prefix
   bsim_, internal ones too (a program linking libbeamsim.a meets no name
   of ours but bsim_...): a function used in one file only is static. What
   the C++ compiler makes of Box2D's classes and the standard library
   (mangled names, _Z...) is not ours to name; an OpenMP critical section's
   lock is named after the section, critical(bsim_...).

Usage: layers.py SOURCE_DIR BUILD_DIR. Prints every breach and exits 1 if
there is one."""
import glob
import os
import re
import subprocess
import sys

# The layers, lowest first; a layer may include from its own and lower ranks,
# never from another folder of the same rank. Every folder of backends/ is
# a layer of rank BACKEND_RANK (backend_ranks adds them), below the registry
# that lists them.
BACKEND_RANK = 2
RANK = {
    "util": 0,
    "model": 1,
    "registry": 3,
    "run": 4,
    "store": 5,
    "figures": 6,
    "video": 6,
    "analysis": 7,
    "cli": 8,
    "bench": 9,
}

# The registry's files: the only ones of src/, include/ and bindings/ that
# name a backend (rule 8).
REGISTRY = ("src/registry/", "include/beamsim/backend_registry.h")

# Each public header's layer: the folder that implements it.
PUBLIC = {
    "base": "util",
    "beamsim": "cli",
    "error": "util",
    "limits": "util",
    "override": "util",
    "progress": "util",
    "stats": "util",
    "version": "util",
    "backend": "model",
    "body_shape": "model",
    "contact_flag": "model",
    "backend_registry": "registry",
    "backend_plugin": "registry",
    "stepper": "run",
    "effects": "model",
    "experiment": "model",
    "key_names": "model",
    "landscape": "model",
    "lattice": "model",
    "options": "model",
    "scene": "model",
    "schedule": "model",
    "state": "model",
    "compare": "run",
    "lattice_outcome": "run",
    "sweep": "run",
    "trajectory": "run",
    "trial": "run",
    "compare_dir": "store",
    "output": "store",
    "trial_fields": "store",
    "regress": "store",
    "replay": "store",
    "report": "store",
    "run_output": "store",
    "run_record": "store",
    "sweep_dir": "store",
    "table": "store",
    "figures": "figures",
    "video": "video",
    "accuracy": "analysis",
    "essay_compare": "analysis",
    "landscape_barriers": "analysis",
    "markov_nearest": "analysis",
    "markov": "analysis",
}

MAX_C_FILES = 25


def layer_of(path):
    """The layer of a source or header path relative to the source dir."""
    parts = path.split("/")
    if parts[0] == "include":
        name = os.path.basename(path).split(".")[0]
        return PUBLIC.get(name)
    if parts[0] in ("src", "backends") and len(parts) == 3:
        return parts[1]
    return None


def may_include(frm, to):
    if frm == to:
        return True
    return RANK[to] < RANK[frm]


def check_includes(src, breaches):
    files = []
    for pat in ("src/*/*.[ch]", "backends/*/*.[ch]", "backends/*/*.cpp", "include/beamsim/*.h",
                "include/beamsim/*.h.in"):
        files += glob.glob(os.path.join(src, pat))
    for f in sorted(files):
        rel = os.path.relpath(f, src)
        frm = layer_of(rel)
        if frm is None:
            breaches.append(f"{rel}: a public header in no layer (add it to PUBLIC in "
                            f"tests/layers.py and docs/architecture.md)")
            continue
        if frm not in RANK:
            breaches.append(f"{rel}: folder {frm} is no layer (RANK in tests/layers.py)")
            continue
        text = open(f, encoding="utf-8").read()
        for m in re.finditer(r'^#\s*include\s+"(\w+)/([\w.]+)"', text, re.M):
            folder, name = m.group(1), m.group(2)
            if folder == "beamsim":
                to = PUBLIC.get(name.split(".")[0])
                if to is None:
                    breaches.append(f"{rel}: includes beamsim/{name}, which is in no layer")
                    continue
            else:
                to = folder
            if to not in RANK:
                breaches.append(f"{rel}: includes {folder}/{name} from no layer")
            elif not may_include(frm, to):
                breaches.append(f"{rel} ({frm}) includes {folder}/{name} ({to}): "
                                f"a layer includes only from the layers below it")


def strip_comments(text):
    return re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)


def read_objects(src, build):
    """{object name: (defined symbols, used symbols)} of the library; the
    objects of sources since removed, which an incremental build leaves
    behind, not among them."""
    objs = glob.glob(os.path.join(build, "CMakeFiles", "bsim_*.dir", "**", "*.o"),
                     recursive=True)
    table = {}
    for o in objs:
        name = re.sub(r"\.o$", "", o.split(".dir" + os.sep, 1)[1])
        if not os.path.exists(os.path.join(src, name)):
            continue
        out = subprocess.run(["nm", o], capture_output=True, text=True, check=True).stdout
        d, u = set(), set()
        for line in out.splitlines():
            p = line.split()
            if len(p) == 3 and p[1] in "TDRBCV":
                d.add(p[2])
            elif len(p) == 2 and p[0] == "U":
                u.add(p[1])
        table[name] = (d, u)
    return table


def check_homes(src, objects, breaches):
    owner = {s: n for n, (d, _) in objects.items() for s in d}
    for h in sorted(glob.glob(os.path.join(src, "include", "beamsim", "*.h"))):
        rel = os.path.relpath(h, src)
        layer = layer_of(rel)
        if layer is None or layer == "cli":
            continue
        text = strip_comments(open(h, encoding="utf-8").read())
        for name in sorted(set(re.findall(r"\b(bsim_\w+)\s*\(", text))):
            home = owner.get(name)
            if home is None:
                continue
            got = layer_of(home.replace(".c", "").replace(".cpp", "") + ".c")
            if got != layer:
                breaches.append(f"{rel} ({layer}) declares {name}, defined in {home} ({got})")


def check_prefix(objects, breaches):
    for name, (defined, _) in sorted(objects.items()):
        for sym in sorted(defined):
            # .gomp_critical_user_NAME: OpenMP's lock of a critical(NAME)
            if not sym.startswith(("bsim_", "_Z", "_", "DW.", ".gomp_critical_user_bsim_")):
                breaches.append(f"{name}: defines the global symbol {sym} without the prefix "
                                "bsim_ (make it static, or name it bsim_...)")


def check_calls(objects, breaches):
    if not objects:
        breaches.append("no object files of the library found")
        return
    defined = {n: d for n, (d, _) in objects.items()}
    used = {n: u for n, (_, u) in objects.items()}
    owner = {s: n for n, d in defined.items() for s in d}
    graph = {n: sorted({owner[s] for s in used[n] if s in owner and owner[s] != n})
             for n in defined}
    # Tarjan's strongly connected components, iteratively.
    index, low, on, stack, comps = {}, {}, set(), [], []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            v, i = work.pop()
            if i == 0:
                index[v] = low[v] = counter
                counter += 1
                stack.append(v)
                on.add(v)
            recurse = False
            for j in range(i, len(graph[v])):
                w = graph[v][j]
                if w not in index:
                    work.append((v, j + 1))
                    work.append((w, 0))
                    recurse = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if recurse:
                continue
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    comps.append(sorted(comp))
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[v])
    for c in comps:
        breaches.append("a circle of calls between files: " + ", ".join(c))


def check_sizes(src, breaches):
    for d in sorted(glob.glob(os.path.join(src, "src", "*"))):
        n = len(glob.glob(os.path.join(d, "*.c")))
        if n > MAX_C_FILES:
            breaches.append(f"{os.path.relpath(d, src)}: {n} .c files (at most {MAX_C_FILES})")


def check_guards(src, breaches):
    headers = glob.glob(os.path.join(src, "include", "beamsim", "*.h"))
    headers += glob.glob(os.path.join(src, "include", "beamsim", "*.h.in"))
    headers += glob.glob(os.path.join(src, "src", "*", "*.h"))
    headers += glob.glob(os.path.join(src, "backends", "*", "*.h"))
    headers += glob.glob(os.path.join(src, "tests", "*.h"))
    headers += glob.glob(os.path.join(src, "tests", "fuzz", "*.h"))
    for h in sorted(headers):
        rel = os.path.relpath(h, src)
        parts = rel.split("/")
        name = parts[-1].split(".")[0].upper()
        if parts[0] == "include":
            want = f"BSIM_{name}_H"
        else:
            want = f"BSIM_{parts[-2].upper()}_{name}_H"
        m = re.search(r"^#ifndef (\w+)\n#define (\w+)", open(h, encoding="utf-8").read(), re.M)
        if not m or m.group(1) != want or m.group(2) != want:
            got = m.group(1) if m else "none"
            breaches.append(f"{rel}: header guard {got}, expected {want}")


def check_umbrella(src, breaches):
    inc = os.path.join(src, "include", "beamsim")
    umbrella = open(os.path.join(inc, "beamsim.h"), encoding="utf-8").read()
    names = {os.path.basename(h) for h in glob.glob(os.path.join(inc, "*.h"))}
    names |= {os.path.basename(h)[:-3] for h in glob.glob(os.path.join(inc, "*.h.in"))}
    for n in sorted(names - {"beamsim.h"}):
        if f'#include "beamsim/{n}"' not in umbrella:
            breaches.append(f"include/beamsim/beamsim.h does not include beamsim/{n}")


def check_defaults(src, breaches):
    text = ""
    for h in sorted(glob.glob(os.path.join(src, "include", "beamsim", "*.h"))):
        text += strip_comments(open(h, encoding="utf-8").read())
    for name in sorted(set(re.findall(r"typedef struct (bsim_\w+_(?:def|config)) \{", text))):
        if not re.search(r"\b" + name + r"_default\s*\(\s*void\s*\)", text):
            breaches.append(f"{name} has no default function {name}_default(void)")


def backend_names(src):
    """The backends: the folders of backends/."""
    return sorted(os.path.basename(d) for d in glob.glob(os.path.join(src, "backends", "*"))
                  if os.path.isdir(d))


def backend_ranks(src, breaches):
    for name in backend_names(src):
        if name in RANK:
            breaches.append(f"backends/{name}: a backend named as a layer of src/")
        RANK[name] = BACKEND_RANK


# A C comment, a C string or character literal; the rest is code.
C_TOKEN = re.compile(r"/\*.*?\*/|//[^\n]*|\"(?:\\.|[^\"\\\n])*\"|'(?:\\.|[^'\\\n])*'", re.S)


def comment_spans(text, python):
    """(start, end) of the comments of a C or Python source."""
    if python:
        return [m.span() for m in re.finditer(r"#[^\n]*", text)]
    return [m.span() for m in C_TOKEN.finditer(text) if m.group(0)[0] == "/"]


def check_backend_names(src, breaches):
    names = backend_names(src)
    files = []
    for top in ("src", "include", "bindings"):
        for f in glob.glob(os.path.join(src, top, "**", "*"), recursive=True):
            if os.path.isfile(f) and re.search(r"\.(c|h|cpp|in|py|m|txt)$", f):
                files.append(f)
    for f in sorted(files):
        rel = os.path.relpath(f, src)
        if rel.startswith(REGISTRY):
            continue
        text = open(f, encoding="utf-8", errors="replace").read()
        spans = comment_spans(text, f.endswith(".py"))
        for name in names:
            word = r"(?<![\w/.-])%s(?![\w/-])" % re.escape(name)
            for m in re.finditer(r"\bbsim_backend_%s\b|%s" % (re.escape(name), word), text):
                in_comment = any(a <= m.start() < b for a, b in spans)
                if in_comment and text.startswith(" backend", m.end()):
                    continue
                line = text.count("\n", 0, m.start()) + 1
                breaches.append(f"{rel}:{line}: names the backend {name} "
                                f"({m.group(0)}): only the registry ({REGISTRY[0]}) does; "
                                f"use bsim_backend_default(), bsim_backend_find or the list")


def main():
    if len(sys.argv) != 3:
        print(__doc__.splitlines()[-2], file=sys.stderr)
        return 2
    src, build = sys.argv[1], sys.argv[2]
    breaches = []
    backend_ranks(src, breaches)
    check_includes(src, breaches)
    objects = read_objects(src, build)
    check_calls(objects, breaches)
    check_prefix(objects, breaches)
    check_homes(src, objects, breaches)
    check_sizes(src, breaches)
    check_guards(src, breaches)
    check_umbrella(src, breaches)
    check_defaults(src, breaches)
    check_backend_names(src, breaches)
    for b in breaches:
        print(b)
    print(f"layers: {len(breaches)} breach(es)")
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main())
