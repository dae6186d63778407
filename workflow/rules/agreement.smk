# Stage 6: agreement of analytic and numeric safe basins (Figs 13-17).
# numeric safe = escape_cycle_energy > cycles; analytic safe = not escapes (slow flow).


rule agreement:
    """IoU and pixel agreement per threshold (Figs 13-15) or per F (Figs 16-17), stored as data
    variables and attributes of the final chart dataset."""
    input:
        params=param_file,
        chart="results/data/numeric/parts/{experiment}/chart.nc",
        basin="results/data/analytic/basin_{experiment}.nc",
    output:
        "results/data/numeric/chart_{experiment}.nc",
    log:
        "results/logs/agreement/{experiment}.log",
    wildcard_constraints:
        experiment=alternatives(AGREEMENT_EXPERIMENTS),
    script:
        "../../scripts/agreement.py"
