# Figure rules (one per paper figure). Placeholder until the figures land.
FIGURE_TARGETS = []


rule figures:
    input:
        FIGURE_TARGETS,
