"""Named checks for the plain-python3 tests: each prints ok/FAIL; summary()
prints 'N passed, M failed' and returns the exit status (0 only if at least
one check ran and none failed)."""

_counts = {"passed": 0, "failed": 0}


def check(name, ok, detail=""):
    if ok:
        _counts["passed"] += 1
        print(f"ok   {name}")
    else:
        _counts["failed"] += 1
        print(f"FAIL {name}{': ' + str(detail) if detail else ''}")


def summary():
    print(f"{_counts['passed']} passed, {_counts['failed']} failed")
    return 0 if _counts["failed"] == 0 and _counts["passed"] > 0 else 1
