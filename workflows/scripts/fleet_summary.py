"""The fleet summary: one row per robot's `imscal run` folder (FORMAT.md, run folders).

Columns: the robot, each stage's status, the mounting verdict, per verification path the
maximum path deviation before and after the precontrol [mm] and its reduction [%], and the
parameter table's version (schema version, the imscal that wrote it, its SHA-256).
Run by Snakemake (snakemake.input: the run folders; snakemake.output: fleet.csv, fleet.md) or
by hand: python3 fleet_summary.py OUT.csv OUT.md RUN_FOLDER...
"""
import csv
import hashlib
import json
import os
import sys

STAGES = ["validate", "calibrate", "identify", "verify", "diagnose", "report"]


def read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def stage_status(run, stage):
    path = os.path.join(run, stage, "stage.json")
    return read_json(path)["status"] if os.path.exists(path) else "not run"


def mounting_verdict(run):
    path = os.path.join(run, "calibrate", "mounting_report.json")
    return read_json(path)["verdict"] if os.path.exists(path) else ""


def table_version(run):
    path = os.path.join(run, "identify", "parameters.json")
    if not os.path.exists(path):
        return {"table_schema_version": "", "table_created_by": "", "table_sha256": ""}
    with open(path, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    table = read_json(path)
    return {"table_schema_version": table["schema_version"],
            "table_created_by": table["created_by"], "table_sha256": digest}


def path_figures(run):
    """Per verified path: before/after [mm] and the reduction [%] of its maximum deviation."""
    figures = {}
    verify = os.path.join(run, "verify")
    if not os.path.isdir(verify):
        return figures
    for path in sorted(os.listdir(verify)):
        file = os.path.join(verify, path, "verification.json")
        if not os.path.exists(file):
            continue
        cases = {c["case"]: c for c in read_json(file)["cases"]}
        before, after = cases["uncompensated"], cases["compensated"]
        figures[f"{path}_before_mm"] = before["max_path_deviation_mm"]
        figures[f"{path}_after_mm"] = after["max_path_deviation_mm"]
        figures[f"{path}_reduction_percent"] = after["reduction_of_max_path_deviation_percent"]
    return figures


def robot_row(run):
    row = {"robot": os.path.basename(os.path.normpath(run))}
    row.update({f"{stage}_status": stage_status(run, stage) for stage in STAGES})
    row["mounting_verdict"] = mounting_verdict(run)
    row.update(path_figures(run))
    row.update(table_version(run))
    return row


def markdown(rows, columns):
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        cells = []
        for c in columns:
            value = row.get(c, "")
            cells.append(f"{value:.3f}" if isinstance(value, float) else str(value))
        lines.append("| " + " | ".join(cells) + " |")
    return "# Fleet summary\n\n" + "\n".join(lines) + "\n"


def write_summary(runs, csv_path, md_path):
    rows = [robot_row(run) for run in runs]
    columns = []
    for row in rows:
        columns += [c for c in row if c not in columns]
    # Written beside and renamed: a reader never sees half a summary.
    with open(csv_path + ".tmp", "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=columns, restval="", lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    with open(md_path + ".tmp", "w", encoding="utf-8") as f:
        f.write(markdown(rows, columns))
    os.replace(csv_path + ".tmp", csv_path)
    os.replace(md_path + ".tmp", md_path)


if "snakemake" in globals():
    write_summary(list(snakemake.input), snakemake.output[0], snakemake.output[1])
elif __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit("usage: fleet_summary.py OUT.csv OUT.md RUN_FOLDER...")
    write_summary(sys.argv[3:], sys.argv[1], sys.argv[2])
