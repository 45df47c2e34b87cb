#!/usr/bin/env bash
# Mutation run (issues 13 and 21) with mutmut 3. Not part of CI: hours on two cores for
# the default modules; pass modules to run a part.
#
#   benchmarks/mutation/run.sh [MODULE.py ...]      (default: the list below)
#   SAMPLE=0.1 SEED=0 benchmarks/mutation/run.sh     (a seeded 10 % of each module's mutants)
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
cd "$ROOT"
MUTMUT="${MUTMUT:-mutmut}"
MODULES=("$@")
if [ ${#MODULES[@]} -eq 0 ]; then
  # The physics models and mechanisms (issue 13), and the modules of issue 21: the
  # formulations, every mechanism, the drive, the relaxation, the catalogue search, the
  # fronts, the store and the units.
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
    optdesign/mechanisms/*.py
    optdesign/formulations/*.py
    optdesign/problem/drive.py
    optdesign/problem/drive_requirements.py
    optdesign/formulations/nlp/relaxation.py
    optdesign/formulations/catalogue/search.py
    optdesign/studies/pareto/*.py
    optdesign/storage/*.py
    optdesign/units.py
    optdesign/reports/display_units.py
  )
fi
# The tests a mutant faces: by default the whole fast suite (the README's test command,
# `-m "not slow"`); mutmut runs, for each mutant, only the tests that called the mutated
# function. SUBSET=1 takes the quicker physics subset of issue 13 instead.
if [ "${SUBSET:-0}" = "1" ]; then
  TESTS=(
    tests/mechanisms/test_crank_slider.py
    tests/mechanisms/test_fork.py
    tests/mechanisms/test_joints.py
    tests/mechanisms/test_pivoting_screw.py
    tests/models/test_loads.py
    tests/models/test_ratio.py
    tests/models/test_screw.py
    tests/models/test_screw_efficiency.py
    tests/models/test_roller_screw.py
    tests/models/test_stiffness.py
    tests/models/test_lock.py
    tests/models/test_error_budget.py
    tests/reproduce/test_monte_carlo.py
    tests/reproduce/test_duan2017.py
    tests/problem/test_design_problem.py
    tests/problem/test_drive.py
    tests/problem/test_drive_requirements.py
    tests/studies/test_solve.py::test_fork_pin_sized_by_single_shear
    tests/studies/test_solve.py::test_fork_optimum_backlash_from_the_iso_formula_and_hertz_by_hand
    tests/studies/pareto/test_pareto.py::test_three_objective_front_small
  )
else
  TESTS=(tests)
fi
rm -rf "$WORK"
mkdir -p "$WORK"
# The whole tracked tree: tests read the examples, docs, README and benchmarks too.
git -C "$ROOT" ls-files -z | (cd "$ROOT" && xargs -0 cp --parents -t "$WORK")
# A precaution: the formulation and solver caches are keyed on the problem, not on the
# code, so a test must not reuse an NLP built before its mutant was selected. Every test
# of the scratch copy starts with empty caches (the figures in docs/testing.md did not
# change with it).
cat >>"$WORK/tests/conftest.py" <<'PY'


@pytest.fixture(autouse=True)
def _empty_formulation_caches():
    from optdesign.runtime import runner as _runner
    from optdesign.formulations.nlp import solve as _solve

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
  # DESELECT: space-separated test ids left out (a test failing on the unmutated tree
  # stops mutmut's first pass).
  for t in ${DESELECT:-}; do printf '    --deselect\n    %s\n' "$t"; done
  # The second hostile corpus runs its cases in a server process: it calls no mutated
  # function in pytest's process (mutmut selects no mutant for it) and takes minutes.
  for t in test_a_hostile_case_of_each_class_ends_as_its_class_requires \
      test_fuzzed_problem_dicts_are_refused_naming_a_touched_field test_the_judge_is_not_blind \
      test_the_corpus_has_every_class_and_a_few_hundred_cases test_known_failures_name_fast_cases \
      test_every_hostile_case_ends_as_its_class_requires; do
    printf '    --deselect\n    tests/test_cli.py::%s\n' "$t"
  done
  printf '    --ignore\n    tests/hostile_classes\n'
  printf "also_copy =\n"
  for f in problems examples docs benchmarks README.md setup.py .ci; do printf '    %s\n' "$f"; done
  echo "use_git_change_detection = false"
} >"$WORK/setup.cfg"
cd "$WORK"
export MPLBACKEND=Agg
# mutmut puts mutants/ on sys.path only if it exists when it starts (a fresh WORK: not yet)
mkdir -p mutants
# Tests that start `python -m optdesign` (signals, CLI) import the mutated tree too, not
# an installed optdesign.
export PYTHONPATH="$WORK/mutants${PYTHONPATH:+:$PYTHONPATH}"
# A mutant's test process that hangs at no CPU (a lock held at mutmut's fork) is stopped
# after IDLE seconds and counted apart ("suspicious"), never as killed.
"$PY" "$ROOT/benchmarks/mutation/watchdog.py" "$WORK/hung.log" "${IDLE:-120}" &
WATCHDOG=$!
trap 'kill $WATCHDOG 2>/dev/null || true' EXIT
if [ -z "${SAMPLE:-}" ]; then
  "$MUTMUT" run --max-children "${JOBS:-2}" >mutmut-run.log 2>&1 || true
  "$MUTMUT" results --all true >mutmut-results.txt 2>&1 || true
  "$PY" "$ROOT/benchmarks/mutation/summary.py" mutmut-results.txt
else
  # A seeded sample, stratified by module (SAMPLE = the fraction of each module's mutants,
  # SEED the sample's seed): every mutant is generated and the tests' coverage collected
  # once (a filter that matches no mutant stops mutmut right after), then only the
  # sample's mutants are run. The kill rate is an estimate; summary.py gives its interval.
  "$MUTMUT" run --max-children "${JOBS:-2}" "no-such-mutant" >mutmut-generate.log 2>&1 || true
  "$MUTMUT" results --all true >mutmut-all.txt 2>&1 || true
  "$PY" "$ROOT/benchmarks/mutation/sample.py" mutmut-all.txt "$SAMPLE" "${SEED:-0}" >sample.txt
  # mutmut takes the names as arguments: in chunks of the shuffled sample, so that the
  # command line stays short and a run stopped early still leaves a random sample
  xargs -a sample.txt -n 40 "$MUTMUT" run --max-children "${JOBS:-2}" >mutmut-run.log 2>&1 || true
  "$MUTMUT" results --all true >mutmut-results-all.txt 2>&1 || true
  sed "s/$/:/" sample.txt >sample-keys.txt  # "name:" so that _mutmut_1 is not _mutmut_12
  grep -F -f sample-keys.txt mutmut-results-all.txt >mutmut-results.txt || true
  "$PY" "$ROOT/benchmarks/mutation/summary.py" mutmut-results.txt
fi
