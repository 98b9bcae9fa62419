# SPDX-License-Identifier: MIT
# Sphinx configuration of the mlcontact documentation site (built by scripts/docs.sh).
# Pages are MyST Markdown; the Python API is autodoc of the built module (build/python), the C++
# API is Doxygen XML read by Breathe (see docs/api/cpp.md for why).
import os
import re
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
BUILD = os.environ.get("MLC_BUILD_DIR", os.path.join(ROOT, "build"))
sys.path.insert(0, os.path.join(BUILD, "python"))

project = "mlcontact"
author = "the mlcontact authors"
copyright = "the mlcontact authors, MIT licence"
with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
    version = release = re.search(r"project\(mlcontact VERSION ([0-9.]+)", f.read()).group(1)

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "breathe",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

# MyST: explicit labels `(label)=`, {ref}/{doc} roles, $..$ and $$..$$ math.
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]

# Math renders offline: MathJax 2 from Debian's libjs-mathjax, copied into the built site by
# scripts/docs.sh (no CDN).
mathjax_path = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
# MyST marks the pages tex2jax_ignore (so that a dollar in the text is no math) and the math it
# parsed with the class `math`; MathJax 2 is told to process exactly those.
myst_update_mathjax = False
mathjax2_config = {
    "tex2jax": {
        "processClass": "tex2jax_process|mathjax_process|math|output_area",
        "ignoreClass": "tex2jax_ignore|mathjax_ignore|document",
    },
}

# Python API: the built extension module; signatures come from pybind11's docstrings.
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_docstring_signature = True

# C++ API: Doxygen XML of the installed headers (scripts/docs.sh runs doxygen first).
breathe_projects = {"mlcontact": os.environ.get("MLC_DOXYGEN_XML",
                                                os.path.join(BUILD, "docs", "doxygen", "xml"))}
breathe_default_project = "mlcontact"
breathe_default_members = ("members",)
# Ignore list for the C++ domain: types from Eigen, the standard library and our dependencies
# that the headers use but this site does not document.
cpp_id_attributes = ["MLC_EXPORT"]
nitpicky = False

# Ignore list: warnings of Sphinx's C++ domain about declarations it cannot parse or sees twice,
# all from Breathe's rendering of valid C++ (Doxygen lists an overload set or a defaulted
# designated initializer in ways the domain's parser does not take). They concern the C++
# reference page only; every other warning stays an error (scripts/docs.sh runs -W).
CPP_DOMAIN_NOISE = (
    "Duplicate C++ declaration",
    "Invalid C++ declaration",
    "Error in postfix expression",
    "Error in declarator or parameters",
    "Error when parsing function declaration",
    "Unparseable C++ cross-reference",
)


class _CppDomainNoise:
    """A logging filter that drops the C++ domain's warnings listed in CPP_DOMAIN_NOISE."""

    def filter(self, record):
        return not str(record.msg).startswith(CPP_DOMAIN_NOISE)


def setup(app):
    import logging
    logging.getLogger("sphinx.sphinx.domains.cpp").addFilter(_CppDomainNoise())

html_theme = "sphinx_rtd_theme"
html_static_path = []  # our only static files (MathJax) are copied in by scripts/docs.sh
html_title = f"mlcontact {release}"
html_theme_options = {"navigation_depth": 3, "collapse_navigation": False}
html_show_sourcelink = False
# Options such as --levels stay as typed in docstrings (no typographic dashes).
smartquotes = False
