# SPDX-License-Identifier: GPL-2.0-or-later
"""The test suite's CPU profile from a STICKSLIP_TEST_CPU log (docs/testing.md): the total,
what two cores would take at best, the files and the tests that cost most.

    STICKSLIP_TEST_CPU=$PWD/cpu.txt ./run.sh test
    .venv/bin/python tools/test_cpu_profile.py cpu.txt [--top 15]
"""
import argparse
import collections


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log")
    ap.add_argument("--top", type=int, default=15)
    args = ap.parse_args(argv)
    tests = {}
    for line in open(args.log):
        seconds, test = line.rstrip("\n").split("\t", 1)
        tests[test] = tests.get(test, 0.0) + float(seconds)  # (a rerun of a test adds up)
    files = collections.Counter()
    for test, s in tests.items():
        files[test.split("::")[0]] += s
    total = sum(tests.values())
    print(f"{len(tests)} tests, {total:.0f} CPU s; on 2 cores at best {total / 2:.0f} s of tests")
    print("\n| CPU s | file |\n|---|---|")
    for f, s in files.most_common(args.top):
        print(f"| {s:.1f} | {f} |")
    print("\n| CPU s | test |\n|---|---|")
    for t, s in sorted(tests.items(), key=lambda kv: -kv[1])[:args.top]:
        print(f"| {s:.1f} | {t} |")


if __name__ == "__main__":
    main()
