# The plant-population study on a workflow engine: one job per plant and step of the lab's chain
# (`imscal population --step`, eval/population_study.hpp), then the summary of the range.
#   snakemake -s workflows/population.smk --configfile workflows/config/population.yaml \
#     --profile workflows/profiles/local        (all cores of this machine)
#   ... --profile workflows/profiles/slurm      (each job through sbatch)
# Config: imscal (the binary), nominal (the nominal robot file), first_seed, last_seed, cycles,
# out (the results folder). A rerun does only what is missing; a failed job's outputs are
# removed by Snakemake and the job is retried as the profile says.

IMSCAL = config.get("imscal", "imscal")
OUT = config["out"]
FIRST, LAST = int(config["first_seed"]), int(config["last_seed"])
SEEDS = list(range(FIRST, LAST + 1))
PLANT = OUT + "/plant-{seed}"
STEP = (
    f"{IMSCAL} population --nominal {config['nominal']} --cycles {config.get('cycles', 10)} "
    f"--out {OUT} --seeds {{wildcards.seed}} --step"
)

wildcard_constraints:
    seed=r"\d+",


rule all:
    input:
        OUT + "/summary.txt",


rule scenarios:
    output:
        directory(PLANT + "/plant"),
    shell:
        STEP + " scenarios"


rule simulate_mounting:
    input:
        rules.scenarios.output,
    output:
        directory(PLANT + "/sim-mounting"),
    shell:
        STEP + " simulate-mounting"


rule simulate_identification:
    input:
        rules.scenarios.output,
    output:
        directory(PLANT + "/sim-identification"),
    shell:
        STEP + " simulate-identification"


rule calibrate:
    input:
        rules.simulate_mounting.output,
    output:
        directory(PLANT + "/calibrate"),
        PLANT + "/unit-calibration.yaml",
    shell:
        STEP + " calibrate"


rule calibrate_frames:
    input:
        rules.calibrate.output,
        rules.simulate_identification.output,
    output:
        directory(PLANT + "/calibrate-frames"),
    shell:
        STEP + " calibrate-frames"


rule identify:
    input:
        rules.calibrate_frames.output,
    output:
        directory(PLANT + "/identify"),
    shell:
        STEP + " identify"


rule verify_seed_line:
    input:
        rules.identify.output,
    output:
        directory(PLANT + "/verify-seed-line"),
    shell:
        STEP + " verify-seed-line"


rule verify_iso9283:
    input:
        rules.identify.output,
    output:
        directory(PLANT + "/verify-iso9283"),
    shell:
        STEP + " verify-iso9283"


rule row:
    input:
        rules.verify_seed_line.output,
        rules.verify_iso9283.output,
    output:
        PLANT + "/row.csv",
    shell:
        STEP + " row"


rule summary:
    input:
        expand(PLANT + "/row.csv", seed=SEEDS),
    output:
        OUT + "/summary.txt",
        OUT + "/population.csv",
    shell:
        f"{IMSCAL} population --nominal {config['nominal']} --cycles {config.get('cycles', 10)} "
        f"--out {OUT} --seeds {FIRST}-{LAST} --step summary"
