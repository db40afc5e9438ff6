# SPDX-License-Identifier: GPL-2.0-or-later
"""What kinds share for `stickslip precision`: a run's figures as relative errors against
the converged reference run's."""


def relative_errors(summary, ref_summary, keys):
    """{name: |summary[key] - ref_summary[key]| / |ref_summary[key]|} for each name: key."""
    return {name: abs(summary[key] - ref_summary[key]) / abs(ref_summary[key]) for name, key in keys.items()}


def angle_errors(suffix):
    """The errors() of a kind whose summary holds its start and stop angles as
    theta_start<suffix> and theta_stop<suffix>."""
    def errors(scene, summary, df, ref_summary, ref_df):
        return relative_errors(summary, ref_summary, {k: f"{k}{suffix}" for k in ("theta_start", "theta_stop")})
    return errors
