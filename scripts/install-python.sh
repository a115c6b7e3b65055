#!/usr/bin/env bash
# Makes `import imscal` work for Debian's python3 of this user: a .pth file in the user's site
# folder naming the built module's folder ($1/python, default build/python). Rebuilding the
# module needs nothing more; removing the .pth file undoes it.
set -euo pipefail
cd "$(dirname "$0")/.."
module_dir="$(pwd)/${1:-build}/python"
python=/usr/bin/python3
ls "$module_dir"/imscal.*.so >/dev/null
site_dir=$("$python" -m site --user-site)
mkdir -p "$site_dir"
echo "$module_dir" >"$site_dir/imscal.pth"
(cd / && "$python" -c 'import imscal; print("import imscal:", imscal.__file__)')
