#!/bin/sh
# Fit the real recorded runs in ../shared/data at L = 0, 1, 2, joint and split
# by pier side, and print a Markdown table (docs/realdata.md was made by it).
# Usage: sh tools/realdata_table.sh [DATA_DIR]
set -u
DATA=${1:-../shared/data}
PMFIT=${PMFIT:-build/pmfit}
[ -d "$DATA" ] || { echo "no $DATA: nothing to fit" >&2; exit 1; }
num() { sed -n "s/.*\"$1\": \([-0-9.e]*\).*/\1/p" | head -1; }
echo "| run | L | P | joint sigma | east sigma (N) | west sigma (N) |"
echo "|---|---|---|---|---|---|"
for f in mmt/k_and_e.dat celestial/gem-28.dat celestial/cgx-l-data.dat; do
  for L in 0 1 2; do
    j=$($PMFIT fit "$DATA/$f" --order $L --json 2>/dev/null)
    js=$(echo "$j" | num sigma_arcsec); p=$(echo "$j" | num n_params)
    s=$($PMFIT fit "$DATA/$f" --order $L --pier split --json 2>&1)
    case "$s" in
      *'"east"'*)
        e=$(echo "$s" | sed 's/"west".*//' | num sigma_arcsec); en=$(echo "$s" | sed 's/"west".*//' | num n_obs)
        w=$(echo "$s" | sed 's/.*"west"//' | num sigma_arcsec); wn=$(echo "$s" | sed 's/.*"west"//' | num n_obs)
        split=$(printf '%.3f" (%s) | %.3f" (%s)' "$e" "$en" "$w" "$wn");;
      *"no observations"*) split="one side only | -";;
      *) side=$(echo "$s" | sed -n 's/.*(pier side \([a-z]*\).*/\1/p')
         why=$(echo "$s" | sed 's/.*hardly separates \([^ ]*\) from \([^ ]*\) (correlation \([-0-9.]*\)).*/\1 ~ \2, r = \3/')
         if [ "$side" = east ]; then split="no convergence: $why | (not fitted)"; else split="(fitted) | no convergence: $why"; fi;;
    esac
    printf '| %s | %s | %s | %.3f" | %s |\n' "$f" "$L" "$p" "$js" "$split"
  done
done
