"""Writes the two tables of the model's power function, crates/core/src/model/pow_tables.rs:

    python3 scripts/gen-pow-tables.py > crates/core/src/model/pow_tables.rs

Each entry is the double nearest to a value computed with 50 significant digits (Python's
decimal module), so the tables depend on no libm. `model/pow.rs` says how they are used.
"""
import struct
from decimal import Decimal, getcontext

getcontext().prec = 50


def bits(x):
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def from_bits(b):
    return struct.unpack("<d", struct.pack("<Q", b))[0]


OFF = 0x3FE6000000000000
N = 256
B = 8
print("// Written by scripts/gen-pow-tables.py; do not edit.")
print()
print("/// `(1/c, -ln(1/c))` for the 256 subintervals of `[0.6875, 1.375)` (`c` their centre),")
print("/// as bits: `1/c` rounded to a double, then `-ln` of that double rounded.")
print("pub(super) const LOG_TABLE: [(u64, u64); 256] = [")
for i in range(N):
    lo = from_bits(OFF + (i << (52 - B)))
    hi = from_bits(OFF + ((i + 1) << (52 - B)))
    c = (Decimal(lo) + Decimal(hi)) / 2
    invc = float(1 / c)
    logc = float(-(Decimal(invc).ln()))
    print(f"    ({bits(invc):#018x}, {bits(logc):#018x}),")
print("];")
print()
print("/// `2^(j/256)` rounded to a double, as bits, less `j << 44` (the exponent bits the")
print("/// reduction adds back).")
print("pub(super) const EXP_TABLE: [u64; 256] = [")
for j in range(N):
    v = float(Decimal(2) ** (Decimal(j) / N))
    print(f"    {bits(v) - (j << (52 - B)):#018x},")
print("];")
