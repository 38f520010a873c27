#!/usr/bin/env bash
# Fill .whl/ (repo root, git-ignored) with what the device call carries: the wheels
# of tools/device/wheels.txt for CPython 3.12 on x86-64 Linux, and a fallback build of
# the solver's C kernel (minvar._lqg_kernel) for CPython 3.12, in case the device
# cannot build it (run.sh builds it there first). Run here, with network or a package
# index; the device has neither. Usage: tools/device/fetch_wheels.sh
#   PY312=/path/to/python3.12  the interpreter the fallback kernel is built against
#                              (default /root/.pyenv/versions/3.12.1/bin/python)
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
exclude=$(git rev-parse --path-format=absolute --git-path info/exclude)
mkdir -p "$(dirname "$exclude")"
grep -qxF '/.whl/' "$exclude" 2>/dev/null || echo '/.whl/' >>"$exclude"
mkdir -p .whl/kernel
rm -f .whl/*.whl

# the device README's command: binary wheels only, no dependencies (each is listed)
mapfile -t pins < <(grep -vE '^\s*(#|$)' tools/device/wheels.txt)
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
    --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 \
    --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
    --platform manylinux1_x86_64 -d .whl "${pins[@]}"

# one wheel per pin: two versions of one package stop the whole install there
found=$(ls .whl/*.whl | wc -l)
if [ "$found" -ne "${#pins[@]}" ]; then
    echo "fetch_wheels: ${#pins[@]} pins but $found wheels in .whl/" >&2
    exit 1
fi
# the pins must be the lock's (a renewed lock renews this list)
for pin in "${pins[@]}"; do
    grep -qixF "$pin" requirements-lock.txt ||
        echo "fetch_wheels: warning: $pin is not in requirements-lock.txt" >&2
done

# fallback kernel: compiled as setup.py's build_ext compiles it (-O3, position
# independent, Python's headers only), against CPython 3.12's ABI (3.12.x alike)
py=${PY312:-/root/.pyenv/versions/3.12.1/bin/python}
read -r inc suffix < <("$py" -c 'import sysconfig as s; print(s.get_paths()["include"], s.get_config_var("EXT_SUFFIX"))')
case $suffix in *cpython-312-x86_64-linux-gnu*) ;; *)
    echo "fetch_wheels: $py is not CPython 3.12 on x86-64 Linux ($suffix)" >&2; exit 1;; esac
${CC:-cc} -O3 -fwrapv -DNDEBUG -fPIC -shared -I"$inc" minvar/_lqg_kernel.c \
    -o ".whl/kernel/_lqg_kernel$suffix"
(cd .whl/kernel && PYTHONPATH= "$py" -c "import _lqg_kernel as k; assert hasattr(k, 'error_cov')")

echo "fetch_wheels: $found wheels and the kernel in .whl/, $(du -sh .whl | cut -f1)"
