#!/usr/bin/env bash
# Mutation run (issue 13) with mutmut 3 over the physics models, the mechanisms and the
# NLP formulation. Not part of CI: minutes to tens of minutes on two cores.
#
#   benchmarks/mutation/run.sh [MODULE.py ...]      (default: the list below)
#
# Works in a scratch copy (WORK, default /tmp/optdesign-mutation) so that neither
# pyproject.toml nor the tree gets mutmut's files; the mutmut configuration is the
# setup.cfg written below. Each mutant runs only the tests (of the fast subset TESTS)
# that call the mutated function (mutmut's own coverage stats). Results:
# WORK/mutmut-results.txt (one line per mutant), summary on stdout.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
WORK="${WORK:-/tmp/optdesign-mutation}"
PY="${PYTHON:-python}"
MUTMUT="${MUTMUT:-mutmut}"
MODULES=("$@")
if [ ${#MODULES[@]} -eq 0 ]; then
  MODULES=(
    optdesign/models/loads.py
    optdesign/models/clearance.py
    optdesign/models/ratio.py
    optdesign/models/screw.py
    optdesign/models/hertz_line.py
    optdesign/models/stiffness.py
    optdesign/models/screw_efficiency.py
    optdesign/models/fork.py
    optdesign/models/crank_slider.py
    optdesign/mechanisms/fork.py
    optdesign/mechanisms/crank_slider.py
  )
fi
# The fast, targeted subset (about 25 s together); slow and CLI tests stay out.
TESTS=(
  tests/test_physics_independent.py
  tests/test_kinematics.py
  tests/test_clearance_and_errors.py
  tests/test_screw_efficiency.py
  tests/test_screw_fits_hertz.py
  tests/test_duan2017.py
  tests/test_stiffness.py
  tests/test_lock.py
  tests/test_shared_subexpressions.py
  tests/test_error_budget.py
  tests/test_pivoting_screw.py
  tests/test_mutation_kills.py
  tests/test_drive.py
  tests/test_drive_requirements.py
)
rm -rf "$WORK"
mkdir -p "$WORK"
cp -r "$ROOT/optdesign" "$ROOT/tests" "$ROOT/problems" "$WORK/"
# A precaution: the formulation and solver caches are keyed on the problem, not on the
# code, so a test must not reuse an NLP built before its mutant was selected. Every test
# of the scratch copy starts with empty caches (the figures in docs/testing.md did not
# change with it).
cat >>"$WORK/tests/conftest.py" <<'PY'


@pytest.fixture(autouse=True)
def _empty_formulation_caches():
    from optdesign.studies import runner as _runner
    from optdesign.studies import solve as _solve

    _solve._NLPS.clear()
    _solve._SOLVERS.clear()
    _runner._CACHE.clear()
    yield
PY
# pytest's markers and options, without a [tool.mutmut] table (mutmut would read it first)
cp "$ROOT/pyproject.toml" "$WORK/"
{
  echo "[mutmut]"
  echo "source_paths = optdesign"
  printf 'only_mutate =\n'
  for m in "${MODULES[@]}"; do printf '    %s\n' "$m"; done
  printf 'pytest_add_cli_args_test_selection =\n'
  for t in "${TESTS[@]}"; do printf '    %s\n' "$t"; done
  printf 'pytest_add_cli_args =\n    -p\n    no:cacheprovider\n    -m\n    not slow\n    -x\n'
  printf "also_copy =\n    problems\n"
  echo "use_git_change_detection = false"
} >"$WORK/setup.cfg"
cd "$WORK"
export MPLBACKEND=Agg
"$MUTMUT" run --max-children "${JOBS:-2}" >mutmut-run.log 2>&1 || true
"$MUTMUT" results --all true >mutmut-results.txt 2>&1 || true
"$PY" "$ROOT/benchmarks/mutation/summary.py" mutmut-results.txt
