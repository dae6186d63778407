"""The Snakemake pipeline's Python side: the registry of experiment kinds (registry, kinds/),
the experiments the package declares (catalog), config validation (config), resolution into
per-experiment parameters (plan, values), the rule-script runtime (runtime) and the cost
estimate (cost).  Importing it is light: no theory or numerics code is loaded until a job runs."""
