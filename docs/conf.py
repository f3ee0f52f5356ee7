# The documentation site: Sphinx with MyST (the Markdown pages), nbsphinx (tutorials as notebooks, executed
# when the site is built: a notebook that fails breaks the build), autodoc (the Python package) and breathe
# (the C++ API from Doxygen's XML). Built by the `docs` target (docs/CMakeLists.txt): it sets HYBRIDCONT_DOXYGEN_XML
# and puts the built Python package on PYTHONPATH.
import os
import sys

project = "hybridcont"
copyright = "the hybridcont developers (BSD-3-Clause)"
author = "the hybridcont developers"
release = os.environ.get("HYBRIDCONT_VERSION", "")

extensions = ["myst_parser", "nbsphinx", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "breathe"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 3
exclude_patterns = ["_build", "**.ipynb_checkpoints", "design/README.md"]

html_theme = "furo"
html_title = "hybridcont"
html_static_path = []

# Notebooks run when the site is built, on the package the build made.
nbsphinx_execute = "always"
nbsphinx_timeout = 300
nbsphinx_kernel_name = "python3"

breathe_projects = {"hybridcont": os.environ.get("HYBRIDCONT_DOXYGEN_XML", "")}
breathe_default_project = "hybridcont"
autodoc_member_order = "bysource"

sys.path.insert(0, os.environ.get("HYBRIDCONT_PYTHON_DIR", ""))
