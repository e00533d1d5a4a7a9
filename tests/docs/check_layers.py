#!/usr/bin/env python3
"""LayersTest — the include rules of docs/architecture.md "Layers", checked on the sources.

  1. Each library includes only its own headers and those of the layers below it
     (core and common at the bottom; io over core; gl over core; service over io and gl;
     http over service; the app over all; the client over common only).
  2. A library's private headers (server/<lib>/private/) are reached only by that library: its
     own include directory adds them; nobody includes "<lib>/private/…" by path. The one
     exception is a test of internals named in ALLOWED_PRIVATE.
  3. The core is pure: no GL, EGL, HTTP, image-library, glTF-library or file-stream includes.
  4. The renderer's public header (gl/renderer.hpp) reaches, through every header it includes,
     no GL/EGL header and not the scene document (core/scene.hpp): it takes render settings.
Prints one line per failure and "N passed, N failed"; exits 1 on any failure.
Usage: check_layers.py SOURCE_DIR
"""
import os
import re
import sys

ALLOWED = {
    "common": {"common"},
    "core": {"core"},
    "io": {"io", "core", "common"},
    "gl": {"gl", "core"},
    "service": {"service", "io", "gl", "core", "common"},
    "http": {"http", "service", "io", "gl", "core", "common"},
    "app": {"app", "http", "service", "io", "gl", "core", "common"},
}
LIBS = set(ALLOWED)
ALLOWED_PRIVATE = {("tests/RendererGLTest.cpp", "gl")}  # the std140 mirrors' test
IMPURE = re.compile(r"#include\s*<(GL/|EGL/|glad/|httplib|OpenImageIO/|png\.h|turbojpeg|jpeglib|"
                    r"webp/|tiny_gltf|fstream|openssl/)")
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)
SYSTEM = re.compile(r"^\s*#\s*include\s*<([^>]+)>", re.M)


def sources(root, sub):
    for base, _, files in os.walk(os.path.join(root, sub)):
        for f in files:
            if f.endswith((".cpp", ".hpp", ".h")):
                yield os.path.join(base, f)


def resolve(root, path, inc):
    """The file a quoted include names: beside the includer, in its library's private/, or
    under server/."""
    here = os.path.dirname(path)
    for cand in (os.path.join(here, inc), os.path.join(here, "private", inc),
                 os.path.join(root, "server", inc)):
        if os.path.isfile(cand):
            return os.path.normpath(cand)
    return None


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    failures, checks = [], 0
    server = os.path.join(root, "server")
    for lib in sorted(LIBS):
        for path in sources(root, os.path.join("server", lib)):
            rel = os.path.relpath(path, root)
            text = open(path, encoding="utf-8").read()
            for inc in INCLUDE.findall(text):
                checks += 1
                top = inc.split("/")[0] if "/" in inc else None
                if top in LIBS and top not in ALLOWED[lib]:
                    failures.append(f"{rel}: includes \"{inc}\": {lib} may include only {sorted(ALLOWED[lib])}")
                if "/private/" in "/" + inc:
                    failures.append(f"{rel}: includes \"{inc}\" by path: private headers come from the library's own include directory")
            if lib == "core":
                for m in IMPURE.finditer(text):
                    failures.append(f"{rel}: the core includes <{m.group(1)}…> (no GL, HTTP, image or file I/O in the core)")
    # 2. private headers of one library used elsewhere (tests, bench, client)
    private = {}
    for lib in LIBS:
        d = os.path.join(server, lib, "private")
        if os.path.isdir(d):
            for f in os.listdir(d):
                private[f] = lib
    for sub in ("tests", "bench", "client"):
        for path in sources(root, sub):
            rel = os.path.relpath(path, root)
            if rel.startswith(os.path.join("tests", "models")):
                continue
            text = open(path, encoding="utf-8").read()
            for inc in INCLUDE.findall(text):
                checks += 1
                name = os.path.basename(inc)
                lib = private.get(name)
                if lib and (inc == name or inc.startswith(lib + "/")) and (rel, lib) not in ALLOWED_PRIVATE \
                        and not os.path.isfile(os.path.join(os.path.dirname(path), inc)):
                    failures.append(f"{rel}: includes {lib}'s private header {inc}")
                if sub == "client" and "/" in inc and inc.split("/")[0] in LIBS and inc.split("/")[0] != "common":
                    failures.append(f"{rel}: the client includes \"{inc}\": it shares only server/common with the server")
    checks += 1
    if len(private) < 5:
        failures.append(f"expected the libraries' private headers in server/*/private/, found {sorted(private)}")
    # 4. what the renderer's public header drags in
    start = os.path.join(server, "gl", "renderer.hpp")
    seen, todo, system = set(), [start], set()
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        text = open(p, encoding="utf-8").read()
        system.update(SYSTEM.findall(text))
        for inc in INCLUDE.findall(text):
            r = resolve(root, p, inc)
            if r:
                todo.append(r)
    checks += 2
    scene = os.path.normpath(os.path.join(server, "core", "scene.hpp"))
    if scene in seen:
        failures.append("gl/renderer.hpp reaches core/scene.hpp: the renderer takes render settings (core/render_settings.hpp), not documents")
    gl = sorted(s for s in system if s.startswith(("GL/", "EGL/", "glad/")))
    if gl:
        failures.append(f"gl/renderer.hpp reaches GL headers {gl}: public headers include no GL")
    if len(seen) < 4:
        failures.append(f"gl/renderer.hpp's include closure has only {len(seen)} files: is the walk broken?")

    for f in failures:
        print("FAIL", f)
    print(f"layers: {checks - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
