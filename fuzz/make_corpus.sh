#!/bin/sh
# make_corpus.sh - (re)make the seed corpora in fuzz/corpus/ from the
# repository's own files (tests/data, examples) and fixed pseudo-random
# bytes.  Run from the top of the repository after `make` (it uses
# build/pmfit to write model files):   sh fuzz/make_corpus.sh [BUILD_DIR]
# Nothing from ../shared/data is copied (licences); make fuzz adds those
# files at run time when the directory exists.
set -e
B=${1:-build}
C=fuzz/corpus
rm -rf $C
mkdir -p $C/runfile $C/modelfile $C/capi $C/fit $C/explain $C/plan

# ---- run files: one option byte (fuzz/harness_runfile.c), then the file.
opt() { # opt BYTE SRC NAME
    { printf "\\$(printf '%03o' "$1")"; cat "$2"; } > $C/runfile/$3
}
for f in tests/data/*.dat tests/data/*.json tests/data/*.csv; do
    b=$(basename "$f"); opt 0 "$f" "${b%.*}"
done
# the new readers forced (option byte 0xc0: byte 1 = format + 1, equinox << 3)
force() { # force OPTBYTE2 SRC NAME
    { printf '\300'; printf "\\$(printf '%03o' "$1")"; cat "$2"; } > $C/runfile/$3
}
force 4 tests/data/rts2_gpoint.dat forced_rts2                  # rts2
force 12 tests/data/rts2_gpoint_j2000.dat forced_rts2_j2000     # rts2, J2000
force 5 tests/data/mw4_model.json forced_mw4                    # mw4
force 6 tests/data/nina_jnow.csv forced_csv                     # csv
force 22 tests/data/nina_jnow.csv forced_csv_jnow               # csv, JNow
force 7 tests/data/mmt_log.dat forced_mmt                       # mmt
force 7 tests/data/nina_j2000.csv forced_mmt_on_csv             # a wrong format
head -n 12 examples/sim_gem.dat > $B/sim_gem_head.dat
opt 0 $B/sim_gem_head.dat sim_gem_head
opt 1 tests/data/bad_records_skip.dat skip_bad_records          # skip_bad
opt 1 tests/data/bad_all_skipped.dat skip_bad_all               # skip_bad
opt 2 tests/data/tpoint_equat.dat no_refraction                 # refraction off
opt 4 tests/data/tpoint_weather.dat override_plausible          # overrides
opt 8 tests/data/tpoint_south.dat override_absurd
opt 12 tests/data/tpoint_nomet.dat override_extreme
opt 48 tests/data/bad_minutes.dat err_17_bytes                 # 17-byte error buffer
opt 32 tests/data/bad_ra_hours.dat err_1_byte
opt 16 tests/data/bad_first_line.dat err_null
printf '\101# tau delta T D\n1 2 3 4\n5 6 \001 8\n' > $C/runfile/long_line_skip   # 0x41: 70000-digit field
printf '\201# tau delta T D\n1 2 x 4\n' > $C/runfile/repeat_skip_messages          # 0x81: 1001 copies
printf '\000\357\273\277# tau delta T D\r\n1 2 3 4\r\n5 6 7 8\r\n' > $C/runfile/bom_crlf

# ---- explain: one option byte (fuzz/harness_explain.c: bit 0 order 1, bit 1
# pairs off, bits 2-3 folds, bits 4-5 alpha, bit 6 gears), then a run file.
xopt() { # xopt BYTE SRC NAME
    { printf "\\$(printf '%03o' "$1")"; cat "$2"; } > $C/explain/$3
}
xopt 1 tests/data/flip_gem_pm180.dat flip_gem_order1
xopt 0 tests/data/indep_temp_sag_fork.dat fork_order0
xopt 1 tests/data/indep_ho_altaz.dat altaz_order1
xopt 5 tests/data/tpoint_equat.dat tpoint_folds2
xopt 65 tests/data/named_altaz_el_modular.dat altaz_gears
xopt 49 tests/data/four_column.dat four_column_alpha
xopt 1 tests/data/rts2_altaz.dat rts2_altaz
head -n 90 examples/sim_gem.dat > $B/sim_gem_head90.dat
xopt 3 $B/sim_gem_head90.dat sim_gem_pairs_off

# ---- plan: two option bytes (fuzz/harness_plan.c: byte 0 mount, order,
# criterion, sides, slew, added terms; byte 1 layout, k, latitude), then the
# run, horizon or catalogue (layout 3: the three separated by lines "%%").
popt() { # popt BYTE0 BYTE1 NAME FILE...  (several files: joined by "%%" lines)
    b0=$1; b1=$2; name=$3; shift 3
    { printf "\\$(printf '%03o' "$b0")\\$(printf '%03o' "$b1")"; first=1
      for f in "$@"; do [ $first = 1 ] || printf '%%%%\n'; first=0; [ "$f" = - ] || cat "$f"; done
    } > $C/plan/$name
}
popt 4 4 run_order1_k2 $B/sim_gem_head90.dat
popt 0 1 horizon_only examples/horizon.hrz
popt 8 10 catalogue_only_doptimal examples/bright_stars.txt
popt 6 71 altaz_run_horizon_catalogue tests/data/indep_ho_altaz.dat examples/horizon.hrz examples/bright_stars.txt
popt 85 39 fork_meridian_slew_south tests/data/indep_temp_sag_fork.dat - examples/bright_stars.txt
popt 132 7 adds_flip_gem tests/data/flip_gem_pm180.dat examples/horizon.hrz

# ---- model files: written by pmfit, and by hand.
$B/pmfit fit examples/sim_gem.dat --order 0 --save $C/modelfile/order0.pm > /dev/null
$B/pmfit fit examples/sim_gem.dat --order 1 --add ha_periodic:144 --add refraction \
    --add temperature --add hysteresis --add 'i@W' --add ha_periodic_paper:2 --save $C/modelfile/order1_physical.pm > /dev/null
cat > $C/modelfile/altaz_latitude.pm <<'MODEL'
# by hand: an alt-az model with a latitude, comments and blank lines
pm-model 2
mount altaz
order 0
latitude 0.55301

terms 8
term a 1 0 0 1e-4
term b 2 0 0 -2e-4
term c' 3 0 0 0.001
term d 4 0 0 0
term e' 5 0 0 -0.0005
term i 6 0 0 3.5e-05
xterm cot(el) zenith 0 0 0 0 0 0 1e-5
xterm c'*aux1 aux 3 0 0 1 4 0.5 -2e-6
end
MODEL
cat > $C/modelfile/v4_inputs_pier.pm <<'MODEL'
# by hand: version 4, the columns the aux terms read and the pier side
pm-model 4
mount equatorial
order 0
latitude 0.8
input 1 press
input 0 hum.rel-2
pier west
terms 8
term a 1 0 0 1e-4
term b 2 0 0 -2e-4
term c' 3 0 0 0.001
term d 4 0 0 0
term e' 5 0 0 -0.0005
term i 6 0 0 3.5e-05
xterm e'*aux1 aux 5 0 0 0 4 1010 1e-6
xterm c'*aux0 aux 3 0 0 0 3 55 -2e-7
end
MODEL
cat > $C/modelfile/v4_errors.pm <<'MODEL'
# by hand: version 4 with each coefficient's 1-sigma error
pm-model 4
mount altaz
order 0
errors
terms 7
term a 1 0 0 1e-4 2.5e-6
term b 2 0 0 -2e-4 2.5e-6
term c' 3 0 0 0.001 1e-5
term d 4 0 0 0 3e-6
term e' 5 0 0 -0.0005 1e-6
term i 6 0 0 3.5e-05 4e-6
xterm cot(el) zenith 0 0 0 0 0 0 1e-5 2e-6
end
MODEL
cat > $C/modelfile/v5_correlations.pm <<'MODEL'
# by hand: version 5, errors and the correlations of the six terms
pm-model 5
mount equatorial
order 0
errors
correlations
stars_sigma 1.2e-6
terms 6
term a 1 0 0 1e-4 2.5e-6
term b 2 0 0 -2e-4 2.5e-6
term c' 3 0 0 0.001 1e-5
term d 4 0 0 0 3e-6
term e' 5 0 0 -0.0005 1e-6
term i 6 0 0 3.5e-05 4e-6
corr 2 1 -0.25
corr 3 1 0.1 0.2
corr 4 1 0 0 -0.5
corr 5 1 0.05 0 0 0.3
corr 6 1 0 0.1 -0.9 0.4 0
end
MODEL
printf 'pm-model 2\r\nmount equatorial\r\norder 0\r\nterms 6\r\nterm a 1 0 0 0\r\nterm b 2 0 0 0\r\nterm c 3 0 0 0\r\nterm d 4 0 0 0\r\nterm e 5 0 0 0\r\nterm i 6 0 0 0\r\nend\r\n' \
    > $C/modelfile/crlf_zero.pm

# ---- the API targets: fixed pseudo-random bytes (the harnesses read any
# bytes; these only give the fuzzer a start of several lengths).
python3 - "$C" <<'PY'
import random, sys
c = sys.argv[1]
r = random.Random(2026)
for target, lens in (("capi", (24, 64, 128, 256, 512, 1024)), ("fit", (48, 160, 400, 800, 1600))):
    for n in lens:
        b = bytearray(r.getrandbits(8) for _ in range(n))
        if target == "capi":
            b[0], b[1] = n % 2, 3   # a valid mount, order 1
        with open("%s/%s/seed_%d" % (c, target, n), "wb") as f:
            f.write(bytes(b))
PY
du -sh $C/*
