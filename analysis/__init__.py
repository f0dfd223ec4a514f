"""The papers' analysis: one package per paper (``stick``, ``catching``, ``grasping``) and the
modules they share (claims table, runs, series, report, commands)."""

# Where a module of a paper's analysis went when the papers got a package each (issue #40): a
# stored sweep table or sweep file names its metrics, plot and summary functions as
# ``analysis.<module>:<function>``, and ``replay.sweep.worker.load_function`` follows this table
# so that an old one still loads. ``tools/migrate_analysis_names.py`` rewrites stored files.
MOVED = {
    "analysis.stick_claims": "analysis.stick.claims",
    "analysis.stick_figures": "analysis.stick.figures",
    "analysis.stick_throws": "analysis.stick.throws",
    "analysis.ablation_stick": "analysis.stick.ablations",
    "analysis.catch_claims": "analysis.catching.claims",
    "analysis.catch_figures": "analysis.catching.figures",
    "analysis.catch_thesis_claims": "analysis.catching.thesis_claims",
    "analysis.ablation_catch": "analysis.catching.ablations",
    "analysis.ablation_catch_opt": "analysis.catching.ablation_opt",
    "analysis.ablation_throws": "analysis.catching.throws",
    "analysis.grasp_claims": "analysis.grasping.claims",
    "analysis.grasp_figures": "analysis.grasping.figures",
    "analysis.grasp_judge": "analysis.grasping.judge",
    "analysis.grasp_run": "analysis.grasping.run",
    "analysis.ablation_grasp": "analysis.grasping.ablations",
}
