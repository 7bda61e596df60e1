"""A checklist for the script tests of tests/report: each check prints "ok" or "FAIL" with what
it checks (and, on failure, the output that explains it); the test's exit code counts them."""


class Checklist:
    def __init__(self):
        self.failures = 0

    def __call__(self, cond, what, out=""):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            self.failures += 1
            print(out)

    def exit_code(self):
        print("%d failure(s)" % self.failures)
        return 1 if self.failures else 0
