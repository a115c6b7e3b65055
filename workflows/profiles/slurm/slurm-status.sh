#!/usr/bin/env bash
# Snakemake's cluster-status command: prints running, success or failed for Slurm job $1.
# scontrol knows a job until MinJobAge after it ended; sacct (with accounting) after that.
set -uo pipefail
job="$1"
state=$(scontrol show job "$job" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -1)
if [ -z "$state" ] && command -v sacct >/dev/null; then
  state=$(sacct -j "$job" -X -n -o State 2>/dev/null | awk 'NR==1 {print $1}')
fi
case "$state" in
  COMPLETED) echo success ;;
  PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | RESIZING) echo running ;;
  "") echo running ;;  # not known yet (just submitted) or the controller is busy
  *) echo failed ;;
esac
