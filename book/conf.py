"""Sphinx configuration of the course site (``robocourse build`` builds it twice: the student
site and the instructor site). Notebooks arrive already executed; nothing is run here.

Everything a page needs is local: MathJax 3 comes from the ``sphinx-mathjax-offline`` package
(TeX fonts included), the theme bundles its own fonts and icons, and widget JavaScript from CDNs
is switched off, so the site works from ``file://`` with no network.
"""
import os

project = "robokit"
author = "robokit courseware team"
copyright = "robokit courseware team"
site = os.environ.get("ROBOKIT_SITE", "student")
html_title = "robokit course" if site == "student" else "robokit course: instructor site"
html_short_title = "robokit"

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",       # numpydoc-style docstrings
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",    # a local MathJax 3 with its TeX fonts instead of the CDN
]
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "home.md", "instructor_home.md"]

# Notebooks: render as executed by the course build; never execute here.
nb_execution_mode = "off"
nb_ipywidgets_js = {}            # no require.js / widget manager from a CDN (the lessons' sliders
                                 # show their pre-computed static form on the site)
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
suppress_warnings = ["mystnb.unknown_mime_type", "myst.header"]

# Library reference from numpydoc docstrings.
autodoc_member_order = "bysource"
autodoc_typehints = "none"          # the numpydoc sections already give every type
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_param = False         # types as plain text: no cross-reference search per type word (halves the build)
napoleon_use_ivar = True          # dataclass fields: documented once, not twice

html_theme = "sphinx_book_theme"
html_static_path = ["_static"]
html_css_files = ["robokit.css"]
html_copy_source = True          # the download button offers the .ipynb
html_show_sourcelink = False
html_last_updated_fmt = None
# pydata-sphinx-theme logs "invalid theme mode" on a first visit unless a default mode is set
html_context = {"default_mode": "light"}
html_theme_options = {
    "show_toc_level": 2,
    "use_download_button": True,
    "use_fullscreen_button": True,
    "home_page_in_toc": True,
    "show_navbar_depth": 1,
    "navigation_with_keys": False,
}


def _module_docstring_as_text(app, what, name, obj, options, lines):
    """Most subpackage docstrings are a plain-text table of their modules (a name, then aligned
    columns): show those as preformatted text rather than let reStructuredText reflow them."""
    import re

    if what == "module" and any(re.match(r"^[a-z_0-9]+ {2,}\S", line) for line in lines):
        lines[:] = ["::", ""] + ["    " + line for line in lines] + [""]


def setup(app):
    app.connect("autodoc-process-docstring", _module_docstring_as_text)
