# Usage: python3 xtask/scripts/ci_units.py CLONE_DIR (docs/results/ci-time.md).
# RUSTC_BOOTSTRAP=1 lets the stable cargo print its unit graph (an unstable option); a measuring
# tool only, nothing in the build depends on it.
#
# The units each CI step compiles that no earlier step compiled, from `cargo … --unit-graph`
# (nothing is built). A unit's identity is what cargo hashes into its file name: package, target,
# mode, features, profile less its name, platform, and its dependencies' identities.
import json, subprocess, sys, os
def graph(cwd, args):
    env = dict(os.environ, RUSTC_BOOTSTRAP="1")
    out = subprocess.run(["cargo"] + args + ["-Z", "unstable-options", "--unit-graph", "--locked"], cwd=cwd, env=env, capture_output=True, text=True, check=True).stdout
    units = json.loads(out)["units"]
    memo = {}
    def ident(i):
        if i not in memo:
            u = units[i]
            prof = dict(u["profile"]); prof.pop("name")
            memo[i] = hash((u["pkg_id"], u["target"]["name"], tuple(u["target"]["kind"]), u["mode"], tuple(sorted(u["features"])),
                            json.dumps(prof, sort_keys=True), u["platform"], tuple(sorted(ident(d["index"]) for d in u["dependencies"]))))
        return memo[i]
    return {ident(i): units[i] for i in range(len(units))}
def name(u):
    pid = u["pkg_id"]
    if pid.startswith("path+"):
        return pid.split("#")[0].rstrip("/").split("/")[-1]
    return pid.split("#")[-1].split("@")[0]
cwd = sys.argv[1]
seen = set()
built_libs = {}
def is_lib(u):
    return u["mode"] == "build" and any(k in ("lib", "rlib", "proc-macro", "cdylib") for k in u["target"]["kind"])
for step, args in [("cargo clippy --workspace --all-targets", ["clippy", "--workspace", "--all-targets"]),
                   ("cargo xtask deps (cargo run -p xtask)", ["build", "-p", "xtask"]),
                   ("cargo test --workspace", ["test", "--workspace", "--no-run"]),
                   ("cargo xtask hostile's cargo build -p calib", ["build", "-p", "calib"]),
                   ("python: maturin's cargo rustc -p calib-python --lib", ["build", "-p", "calib-python", "--lib"])]:
    g = graph(cwd, args)
    new = {k: u for k, u in g.items() if k not in seen}
    again = sorted({name(u) for u in new.values() if is_lib(u) and name(u) in built_libs})
    print(f"{step}: {len(g)} units, {len(new)} compiled here, of which {len(again)} libraries compiled before in another form:")
    print("   " + ", ".join(again))
    for k, u in new.items():
        if is_lib(u):
            built_libs.setdefault(name(u), []).append(u)
    seen |= set(g)
