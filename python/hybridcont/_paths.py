"""Where the package finds its data: the shipped model files, the figure script and the report's viewer.

The build lays them out in the package (``<build>/python/hybridcont/data``, cmake/python_package.cmake), and
``cmake --install`` and ``pip install`` copy the package whole, so one rule holds everywhere: ``data`` beside
this file.
"""
import os

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
MODELS = os.path.join(DATA, "models")
PLOT_SCRIPT = os.path.join(DATA, "hybridcont_plot.py")
REPORT = os.path.join(DATA, "report")


def report_assets():
    """The files report.html is assembled from (include/hybridcont/study_report.h, ReportAssets)."""
    return {
        "template_html": os.path.join(REPORT, "template.html"),
        "viewer_js": os.path.join(REPORT, "viewer.js"),
        "viewer_css": os.path.join(REPORT, "viewer.css"),
        "plotly_js": os.path.join(REPORT, "plotly-basic.min.js"),
    }
