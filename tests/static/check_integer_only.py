#!/usr/bin/env python3
"""Proves per-frame object files are integer-only and heap-free by reading their aarch64 code.

Fails on:
  fp        floating-point instructions (A64 mnemonics starting with 'f', scvtf/ucvtf, BFloat16
            bf* but not the integer bitfield moves bfi/bfm/bfxil/bfc),
            except fmov between a general register and an FP/SIMD register (a bit move that
            integer NEON code uses);
  softfloat calls to compiler soft-float helpers (long double on aarch64 is software quad);
  libm      calls to math-library functions;
  heap      calls to operator new/delete or the malloc family;
  throw     calls that throw (std::__throw_*, __cxa_throw/allocate_exception).

Usage: check_integer_only.py --objdump OBJDUMP --nm NM [--expect FUNC:KIND,...] OBJ...
With --expect it succeeds only if each named function has a violation of the named kind (used to
prove the checker catches what it claims to).
"""
import argparse
import re
import subprocess
import sys

# bf* are the BFloat16 instructions, except the integer bitfield moves bfi, bfm, bfxil, bfc.
FP_MNEMONIC = re.compile(r"^(f[a-z0-9]*|scvtf|ucvtf|bf[a-z0-9]*)(\.|$)")
INTEGER_BF = {"bfi", "bfm", "bfxil", "bfc"}
GPR = re.compile(r"^(x|w)([0-9]+|zr)$")
SOFTFLOAT = re.compile(r"^__[a-z]*(sf|df|tf|xf|hf|bf)[a-z]*[0-9]*$")
LIBM = re.compile(
    r"^(sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|exp|exp2|expm1|log|log2|log10|log1p|"
    r"pow|sqrt|cbrt|hypot|floor|ceil|trunc|round|lround|llround|rint|lrint|nearbyint|fmod|"
    r"remainder|fabs|fmin|fmax|fma|frexp|ldexp|modf|sincos)[fl]?$")
HEAP = re.compile(r"^(_Zn[wa]|_Zd[la]|malloc$|calloc$|realloc$|free$|aligned_alloc$|"
                  r"posix_memalign$|memalign$|valloc$|strdup$)")
THROW = re.compile(r"^(__cxa_throw$|__cxa_allocate_exception$|_ZSt[0-9]+__throw_)")

INSN = re.compile(r"^\s+[0-9a-f]+:\s+([a-z0-9.]+)\s*(.*)$")
FUNC = re.compile(r"^[0-9a-f]+ <(.+)>:$")
CALL = re.compile(r"^(bl|b)\s+[0-9a-f]+ <([^>+]+)")
RELOC_CALL = re.compile(r"R_AARCH64_(CALL26|JUMP26)\s+(\S+)")


def is_gpr_fmov(operands):
    regs = [r.strip() for r in operands.split("//")[0].split(",")]
    return len(regs) == 2 and any(GPR.match(r) for r in regs)


def classify_symbol(name):
    for kind, pattern in (("softfloat", SOFTFLOAT), ("libm", LIBM), ("heap", HEAP),
                          ("throw", THROW)):
        if pattern.match(name):
            return kind
    return None


def scan(objdump, obj):
    """Yields (function, kind, detail) for each violation in obj."""
    out = subprocess.run([objdump, "-d", "-r", "--no-show-raw-insn", obj], check=True,
                         capture_output=True, text=True).stdout
    func = "?"
    for line in out.splitlines():
        m = FUNC.match(line)
        if m:
            func = m.group(1)
            continue
        r = RELOC_CALL.search(line)
        if r:
            kind = classify_symbol(r.group(2))
            if kind:
                yield func, kind, "call " + r.group(2)
            continue
        m = INSN.match(line)
        if not m:
            continue
        mnemonic, operands = m.group(1), m.group(2)
        if (FP_MNEMONIC.match(mnemonic) and mnemonic not in INTEGER_BF
                and not (mnemonic == "fmov" and is_gpr_fmov(operands))):
            yield func, "fp", (mnemonic + " " + operands).strip()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--objdump", required=True)
    ap.add_argument("--nm", required=True)
    ap.add_argument("--expect", default="")
    ap.add_argument("objects", nargs="+")
    args = ap.parse_args()

    violations = []
    for obj in args.objects:
        for func, kind, detail in scan(args.objdump, obj):
            violations.append((obj, func, kind, detail))
        # Undefined symbols catch calls the disassembly shows only through a PLT or a tail call.
        undefined = subprocess.run([args.nm, "-u", obj], check=True, capture_output=True,
                                   text=True).stdout.split()
        for name in undefined:
            kind = classify_symbol(name)
            if kind:
                violations.append((obj, "(undefined symbol)", kind, name))

    expected = [tuple(s.split(":")) for s in args.expect.split(",") if s]
    if expected:
        missing = [f"{f}:{k}" for f, k in expected
                   if not any(f in v[1] and v[2] == k for v in violations)]
        if missing:
            print("checker missed violations in: " + ", ".join(missing))
            return 1
        kinds = sorted({v[2] for v in violations})
        print(f"checker caught {len(violations)} violations of kinds {', '.join(kinds)}")
        return 0

    for obj, func, kind, detail in violations:
        print(f"{obj}: {func}: {kind}: {detail}")
    if violations:
        print(f"FAIL: {len(violations)} non-integer or heap operations in per-frame code")
        return 1
    print(f"OK: {len(args.objects)} per-frame objects are integer-only and heap-free")
    return 0


if __name__ == "__main__":
    sys.exit(main())
