# A fleet: one `imscal run` per campaign (a robot's session: its run.yaml and the files it
# names), then a fleet summary with each robot's verdicts, path-deviation figures and
# parameter-table version (scripts/fleet_summary.py).
#   snakemake -s workflows/fleet.smk --configfile workflows/config/fleet.yaml \
#     --profile workflows/profiles/local        (or workflows/profiles/slurm)
# Config: imscal (the binary), out (the results folder), campaigns (robot name: its run.yaml).
# `imscal run` exits 1 when a check on the data failed with every output written (a mounting
# verdict of fail): the run is then complete and its verdict goes into the summary; any other
# failure fails the job, whose folder Snakemake removes.

IMSCAL = config.get("imscal", "imscal")
OUT = config["out"]
CAMPAIGNS = config["campaigns"]

wildcard_constraints:
    robot="[A-Za-z0-9_.-]+",


rule all:
    input:
        OUT + "/fleet.csv",


rule run_campaign:
    input:
        lambda wildcards: CAMPAIGNS[wildcards.robot],
    output:
        directory(OUT + "/runs/{robot}"),
    shell:
        IMSCAL + " run {input} --out {output} || [ $? -eq 1 ]"


rule fleet_summary:
    input:
        expand(OUT + "/runs/{robot}", robot=sorted(CAMPAIGNS)),
    output:
        OUT + "/fleet.csv",
        OUT + "/fleet.md",
    script:
        "scripts/fleet_summary.py"
