#!/usr/bin/env python3
"""Writes the bad robot logs of this folder: NAME.csv and NAME.expected (the line, field and
message part that calib::read_robot_log_csv must report). Run from this folder; the output is
committed, this script documents how each case was made."""
J = ["A1", "A2", "A3", "A4", "A5", "A6"]
COLS = ["t_s", "payload_kg"] + [f"q_desired_{j}_rad" for j in J] + [f"q_internal_{j}_rad" for j in J]


def header(version="1", robot="kr16", cycle="0.002"):
    h = []
    if version is not None:
        h.append(f"# imscal-robot-log: {version}")
    if robot is not None:
        h.append(f"# robot: {robot}")
    if cycle is not None:
        h.append(f"# cycle_s: {cycle}")
    return h


def row(k, t=None, payload="5"):
    t = k * 0.002 if t is None else t
    return ([f"{t:.4f}", payload] + [f"{0.1 * i + 0.001 * k:.6f}" for i in range(6)] +
            [f"{0.1 * i + 0.001 * k - 1e-5:.6f}" for i in range(6)])


def rows(n=6):
    return [",".join(row(k)) for k in range(n)]


def changed(k, index, value, n=6):
    r = rows(n)
    x = row(k)
    x[index] = value
    r[k] = ",".join(x)
    return r


cases = {}


def case(name, lines, line, field, contains, comment):
    cases[name] = (lines, line, field, contains, comment)


base = header() + [",".join(COLS)]  # the column header is line 4, data rows from line 5
case("empty", [], 0, "", "the file is empty", "an empty file")
case("no_header_row", header(), 3, "", "no header line", "only comment lines, no column names")
case("missing_version", header(version=None) + [",".join(COLS)] + rows(), 0, "imscal-robot-log",
     "missing header line", "no '# imscal-robot-log' line")
case("unknown_version", header(version="7") + [",".join(COLS)] + rows(), 1, "imscal-robot-log",
     "unknown version '7'", "a future version")
case("other_robot", header(robot="kr6") + [",".join(COLS)] + rows(), 2, "robot",
     "the log is of robot 'kr6'", "a log of another robot")
case("bad_cycle", header(cycle="2ms") + [",".join(COLS)] + rows(), 3, "cycle_s",
     "is not a cycle time", "cycle with a unit in the value")
with_mark = header(cycle="-0.002")
with_mark[0] = "\ufeff" + with_mark[0]
case("byte_order_mark_negative_cycle", with_mark + [",".join(COLS)] + rows(), 3, "cycle_s",
     "is not a cycle time", "a UTF-8 byte-order mark (skipped), then a negative cycle time")
missing = [c for c in COLS if c != "q_internal_A4_rad"]
case("missing_column", header() + [",".join(missing)] +
     [",".join(r[:11] + r[12:]) for r in (row(k) for k in range(6))], 4, "q_internal_A4_rad",
     "missing column", "a joint column missing")
case("extra_column", header() + [",".join(COLS + ["temperature_C"])] +
     [",".join(row(k) + ["25"]) for k in range(6)], 4, "", "15 columns, expected 14",
     "an unknown extra column")
case("duplicate_column", header() + [",".join(COLS[:3] + [COLS[2]] + COLS[4:])] + rows(), 4,
     "q_desired_A1_rad", "appears twice", "a column name twice")
case("semicolons", header() + [",".join(COLS)] + [";".join(row(k)) for k in range(6)], 5, "",
     "';' is not a separator", "semicolon-separated rows (a spreadsheet export)")
truncated = rows()
truncated[-1] = truncated[-1][: len(truncated[-1]) // 2]
case("truncated_mid_line", base + truncated, 10, "", "fields, the header has 14",
     "the last line cut in the middle (interrupted copy), no final newline")
case("non_numeric", base + changed(3, 5, "abc"), 8, "q_desired_A4_rad", "'abc' is not a number",
     "a word in a number column")
case("nan_value", base + changed(2, 3, "nan"), 7, "q_desired_A2_rad", "is not a finite number",
     "NaN joint angle")
case("inf_value", base + changed(2, 10, "inf"), 7, "q_internal_A3_rad", "is not a finite number",
     "Inf joint angle")
case("duplicate_time", base + changed(3, 0, "0.0040"), 8, "t_s", "does not increase",
     "a time stamp repeated")
case("backwards_time", base + changed(3, 0, "0.0010"), 8, "t_s", "does not increase",
     "time going backwards")
case("gap", base + [",".join(row(k, t=(k * 0.002 if k < 3 else k * 0.002 + 0.01))) for k in range(6)],
     8, "t_s", "gap of 0.012 s", "five lost controller cycles")
case("jitter", base + changed(3, 0, "0.0047"), 8, "t_s", "less than half the cycle",
     "a time stamp 0.65 cycles late, so the next step is 0.35 cycles")
case("negative_payload", base + changed(2, 1, "-5"), 7, "payload_kg", "negative payload",
     "a negative payload")
case("no_data", base, 4, "", "no data rows", "header only")
with_empty = rows()
with_empty.insert(2, "")
case("empty_line", base + with_empty, 7, "", "empty line among the data rows",
     "an empty line among the rows")
case("degrees_and_wrong_unit", header() + [",".join(COLS[:2] + [c.replace("_rad", "_mrad") if c == "q_desired_A1_rad" else c for c in COLS[2:]])] + rows(),
     4, "q_desired_A1_mrad", "unknown unit 'mrad'", "a unit the reader does not know (mrad)")

for name, (lines, line, field, contains, comment) in cases.items():
    with open(name + ".csv", "w") as f:
        f.write("\n".join(lines) + ("\n" if lines and name != "truncated_mid_line" else ""))
    with open(name + ".expected", "w") as f:
        f.write(f"# {comment}\nline: {line}\nfield: {field}\ncontains: {contains}\n")
print(len(cases), "cases")
