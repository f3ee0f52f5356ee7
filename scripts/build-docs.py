"""Builds the documentation site (docs/: Sphinx with MyST, nbsphinx, autodoc and breathe) and checks its links.

    /usr/bin/python3 scripts/build-docs.py BUILD_DIR        (the `docs` target and the test `docs.site`)

1. Doxygen's XML of include/hybridcont (for the C++ API pages) into BUILD_DIR/docs/doxygen.
2. sphinx-build with warnings as errors into BUILD_DIR/docs/html, the notebooks executed on the package the
   build made (BUILD_DIR/python): a warning, a failing notebook or a missing reference fails it.
3. Every relative link and image of the pages points at a file of the site, and every #anchor at an id of its
   page. Links to other sites are not followed (the build runs offline).
Exit 0 when all holds; otherwise the failures, one per line, and exit 1.
"""
import html.parser
import os
import subprocess
import sys
import urllib.parse

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def doxygen(build):
    out = os.path.join(build, "docs", "doxygen")
    os.makedirs(out, exist_ok=True)
    config = "\n".join([
        "PROJECT_NAME = hybridcont",
        "INPUT = %s" % os.path.join(SOURCE, "include", "hybridcont"),
        "FILE_PATTERNS = *.h",
        "OUTPUT_DIRECTORY = %s" % out,
        "GENERATE_XML = YES",
        "GENERATE_HTML = NO",
        "GENERATE_LATEX = NO",
        "EXTRACT_ALL = YES",
        "QUIET = YES",
        "WARNINGS = NO",
        "WARN_IF_UNDOCUMENTED = NO",
        "ENABLE_PREPROCESSING = YES",
        "MACRO_EXPANSION = NO",
    ])
    subprocess.run(["doxygen", "-"], input=config, text=True, check=True, cwd=out)
    return os.path.join(out, "xml")


class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        if tag == "a" and attrs.get("name"):
            self.ids.add(attrs["name"])
        for key in ("href", "src"):
            if attrs.get(key):
                self.links.append(attrs[key])


def check_links(site):
    pages = {}
    for root, _, files in os.walk(site):
        for name in files:
            if name.endswith(".html"):
                path = os.path.join(root, name)
                parser = Links()
                with open(path, encoding="utf-8") as f:
                    parser.feed(f.read())
                pages[os.path.normpath(path)] = parser
    failures = []
    for path, parser in sorted(pages.items()):
        for link in parser.links:
            parts = urllib.parse.urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "data:", "javascript:")):
                continue  # another site: not followed offline
            target = path if not parts.path else os.path.normpath(
                os.path.join(os.path.dirname(path), urllib.parse.unquote(parts.path)))
            if os.path.isdir(target):
                target = os.path.join(target, "index.html")
            if not os.path.exists(target):
                failures.append("%s: link to a missing file: %s" % (os.path.relpath(path, site), link))
            elif parts.fragment and target in pages and parts.fragment not in pages[target].ids:
                failures.append("%s: link to a missing anchor: %s" % (os.path.relpath(path, site), link))
    return len(pages), failures


def main(build):
    build = os.path.abspath(build)
    env = dict(os.environ)
    env["HYBRIDCONT_DOXYGEN_XML"] = doxygen(build)
    env["HYBRIDCONT_PYTHON_DIR"] = os.path.join(build, "python")
    env["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"  # the notebook kernel's debugger notes on standard error
    env["PYTHONPATH"] = os.path.join(build, "python") + os.pathsep + env.get("PYTHONPATH", "")
    site = os.path.join(build, "docs", "html")
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           "-d", os.path.join(build, "docs", "doctrees"), os.path.join(SOURCE, "docs"), site], env=env)
    if done.returncode != 0:
        print("sphinx-build failed (warnings are errors)")
        return 1
    n, failures = check_links(site)
    for f in failures:
        print(f)
    print("%d pages, %d broken links; the site is in %s" % (n, len(failures), site))
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: build-docs.py BUILD_DIR")
    sys.exit(main(sys.argv[1]))
