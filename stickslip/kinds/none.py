# SPDX-License-Identifier: GPL-2.0-or-later
"""Kind "none": a scene without headline figures (packings, benchmarks)."""
NAME = "none"
NAMES = {}
PRECISION_DURATION = None
COMPARISON_LAWS = ()
REPORT_TIMINGS = ("step",)


def summarise(scene, df):
    return {}


def errors(scene, summary, df, ref_summary, ref_df):
    return {}


def claims(scene):
    return []


def figures(out, runs):
    return []


def precision_figures(out, runs):
    return []


def paper_statements(scene):
    return []
