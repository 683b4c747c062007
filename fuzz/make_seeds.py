#!/usr/bin/env python3
"""Writes fuzz/seeds/<target>/ and fuzz/dicts/*.dict from the repository's examples.
Run from anywhere: python3 fuzz/make_seeds.py (GLB seeds are added by README's commands)."""
import glob, json, os, re, struct
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
ex = os.path.join(root, "examples")

def out(target, name, data):
    d = os.path.join(here, "seeds", target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)

jsons = sorted(glob.glob(os.path.join(ex, "**", "*.json"), recursive=True))
tomls = sorted(glob.glob(os.path.join(ex, "**", "*.toml"), recursive=True))
keys, strings = set(), set()
def walk(v):
    if isinstance(v, dict):
        for k, x in v.items():
            keys.add(k); walk(x)
    elif isinstance(v, list):
        for x in v: walk(x)
    elif isinstance(v, str) and len(v) < 40:
        strings.add(v)

for p in jsons:
    text = open(p).read()
    name = os.path.relpath(p, ex).replace("/", "-")
    out("genome", name, text)
    g = json.loads(text)
    walk(g)
    if g.get("model") == "lsystem":
        for comp in ("shoot", "root"):
            c = g[comp]
            out("lsystem_rules", f"{name}-{comp}", "\n".join([c["axiom"]] + c["rules"]) + "\n")
    if g.get("model") == "automata":
        out("sexpr", name, g["program"])
    if g.get("model") == "plantmaker":
        garden = {"model": "plantmaker-garden", "format": 1, "area": [30, 20],
                  "placement_seed": 1, "max_tries": 1000,
                  "plants": [{"genome": g, "seeds": [1, 2, 3]}]}
        out("garden", name, json.dumps(garden, indent=2))
        out("input_error", name, struct.pack("<QQ", 3, 7) + text.encode())
# A garden of every PlantMaker example.
pm = [json.loads(open(p).read()) for p in jsons if '"plantmaker"' in open(p).read()]
out("garden", "all.json", json.dumps({"model": "plantmaker-garden", "format": 1, "area": [50.5, 40],
    "placement_seed": 9, "plants": [{"genome": g, "seeds": [i]} for i, g in enumerate(pm)]}))
for p in tomls:
    text = open(p).read()
    name = os.path.relpath(p, ex).replace("/", "-")
    out("config", name, text)
    out("experiment", name, text)
    out("input_error", name, struct.pack("<QQ", 5, 2) + text.encode())
    for m in re.finditer(r"^\s*\[*([A-Za-z0-9_.-]+)\]*\s*=?", text, re.M):
        for k in m.group(1).split("."):
            keys.add(k)
for p in glob.glob(os.path.join(ex, "**", "*.packed"), recursive=True):
    out("packed", os.path.basename(p), open(p).read())

# Hand-written inputs.
sexprs = {
    "two": "(Top (Seq (RotateH 3.2) (Wait)) (Killme))",
    "bare": "(Top Wait Killme)",
    "create": "(Top (Repeat 5 (Seq (PushPop (Seq (RotateL 0.5) (CreateAutomaton A2))) (Wait))) (Seq (Assign Var1 2) (RepeatIndex 3 Var2 (Seq (RotateU 1e-3) (CreateAutomaton Leaf)))))",
    "ifs": "(Top (IfLess Var1 0.5 (Seq (Add Var1 1) (Wait)) (IfEqual Length -0.05 (Multiply Thickness 0.9) (IfGreater Var3 10 (CreateAutomaton Flower) (Killme)))))",
    "comment": "; a comment\n(Top\n  (Seq (Assign Length 2) ; grow\n       (Repeat 10 (Wait))))\n",
}
for k, v in sexprs.items():
    out("sexpr", k, v)
rules = {
    "paper": "A\nA -> [>b[B]A]$$$$[>b[B]A]\nB -> bl\n",
    "root": "[A]\nA -> c[+r][-r]B\nB -> cr\n",
    "empty": "A\n",
    "spaces": " [ A ] \n A -> < b [ + l ] [ - l ] A \n",
    "many": "AB\nA -> B\nB -> C\nC -> D\nD -> [&b]$[<l]A\n",
}
for k, v in rules.items():
    out("lsystem_rules", k, v)
for k, (a, b, t) in {
    "line0": (0, 0, "abc"), "end": (2, 100, "a\nbc}\n"), "utf8": (1, 2, "é}ü\n"),
    "big": (0xffffffffffffffff, 0xffffffffffffffff, "x"), "empty": (1, 1, ""),
    "closing": (1, 4, '{"a": }'), "missing": (3, 1, "{\n\"a\": 1\n]"),
}.items():
    out("input_error", k, struct.pack("<QQ", a, b) + t.encode())

# Dictionaries.
def dict_file(name, words):
    with open(os.path.join(here, "dicts", name), "w") as f:
        for w in sorted(words):
            esc = "".join(c if (32 <= ord(c) < 127 and c not in '"\\') else
                          "".join(f"\\x{b:02x}" for b in c.encode()) for c in w)
            f.write('"' + esc + '"\n')
json_words = {f'"{k}"' for k in keys} | {f'"{s}"' for s in strings} | {
    "{", "}", "[", "]", ":", ",", "true", "false", "null", "1e308", "-1e308", "1e-320",
    "18446744073709551615", "-1", "0.0", "4294967295", "NaN", "\\u0000", '"model"', '"format"',
    '"plantmaker-garden"', '"bintree"', '"automata"', '"plantmaker"', '"lsystem"'}
dict_file("json.dict", json_words)
# Checkpoints: the keys of the saved runs in seeds/checkpoint (made with `sylva evolve`).
ck = set()
def walk_keys(v):
    if isinstance(v, dict):
        for k, x in v.items():
            ck.add(f'"{k}"'); walk_keys(x)
    elif isinstance(v, list):
        for x in v: walk_keys(x)
for p in glob.glob(os.path.join(here, "seeds", "checkpoint", "*")):
    walk_keys(json.load(open(p)))
dict_file("checkpoint.dict", json_words | ck | {'"crossover+mutation"', '"random"', '"mutation"', '"crossover"',
    '"0000000000000000000000000000000000000000000000000000000000000000"'})
toml_words = {k for k in keys} | {f'"{s}"' for s in strings} | {
    "[", "]", "[[", "]]", " = ", "=", "true", "false", "inf", "nan", "-inf", "1e308", "0x7fffffffffffffff",
    "9223372036854775807", "-9223372036854775808", "'''", '"""', "\n", "{", "}", "1979-05-27T07:32:00Z",
    "model", '"bintree"', '"automata"', '"plantmaker"', '"lsystem"', "herbs-under-tree", "lateral-light", "empty-rules"}
dict_file("toml.dict", toml_words)
dict_file("sexpr.dict", {"(", ")", "Top", "Seq", "IfLess", "IfGreater", "IfEqual", "PushPop", "Repeat",
    "RepeatIndex", "RotateH", "RotateL", "RotateU", "CreateAutomaton", "Assign", "Add", "Multiply",
    "Wait", "Killme", "Length", "Thickness", "Var1", "Var2", "Var3", "Var4", "A1", "A2", "A8", "A99",
    "Leaf", "Flower", "10", "-10", "1e-3", "1e38", "NaN", "inf", ";", "\n", "(Wait)", "(Killme)"})
dict_file("lsystem.dict", {"->", " -> ", "[", "]", "+", "-", "<", ">", "$", "&", "l", "b", "r", "c",
    "A", "B", "Z", "\n", "[A]", "A -> ", "B -> "})
dict_file("packed.dict", {"plantmaker 1", "seed ", "branch ", "fan ", "inflorescence ", "#", "\n", " ",
    "4294967295", "18446744073709551615", "-1", "#ffffff", "#d81e2c", "10000", "00001", "358", "0", "1", "99999999999"})
dict_file("glb.dict", {"glTF", "JSON", "BIN\x00", '"nodes"', '"children"', '"mesh"', '"meshes"', '"matrix"',
    '"translation"', '"rotation"', '"scale"', '"accessors"', '"bufferView"', '"bufferViews"', '"byteOffset"',
    '"byteStride"', '"byteLength"', '"componentType"', '"count"', '"type"', '"SCALAR"', '"VEC2"', '"VEC3"',
    '"VEC4"', '"MAT4"', '"primitives"', '"attributes"', '"POSITION"', '"NORMAL"', '"TEXCOORD_0"', '"COLOR_0"',
    '"indices"', '"material"', '"materials"', '"mode"', '"buffer"', '"buffers"', '"uri"', '"scene"', '"scenes"',
    '"images"', '"textures"', '"samplers"', '"extras"', '"genome"', '"normalized"', '"sparse"', '"min"', '"max"',
    "5120", "5121", "5122", "5123", "5125", "5126", "34962", "34963", "4294967295", "-1", "1e39",
    "18446744073709551615", "9223372036854775807", "9007199254740993", "65535", "2147483648"})
