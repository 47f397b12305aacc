#!/usr/bin/python3
"""The documentation stays in step with the code (catkin_make run_tests, no ROS master needed).

- doc/ros_api.md lists every parameter a node reads, and reads nothing it does not list. The
  reads are found in every C++ and Python file under src/, include/ and scripts/, wherever the
  code sits: roscpp's getParam, param, hasParam, searchParam, ros::param::get/has, any helper
  that forwards its name argument to one of them (found, not listed: requiredParam and
  optionalParam today), a loop over a list of names, rospy's get_param/has_param/search_param,
  and dynamic_reconfigure's cfg/*.cfg. A read whose name this test cannot tell fails it, so a
  new way of reading parameters has to be taught here instead of slipping through.
- A default the code gives as a plain literal is one of the defaults the document gives.
- Every node executable, nodelet and node script of the package has a section there, and each
  <param> a launch file gives one of its nodes is listed in that node's section.
- Every launch file has a section in doc/ros_api.md's "Launch files" that names each of its
  arguments (every <arg> of the file's own that has no fixed value); a table of arguments names
  only arguments the file has, and gives each plain default (not a $(...) expression) the file gives.
- What the pages show scenario_info printing (a console block's `$ rosrun ... scenario_info`
  and the lines after it) is what it prints: its advice and the pages' stay the same.
- Every relative link in README.md and doc/*.md reaches an existing file and heading.
- No other page keeps a parameter table of its own (one list), and README.md has at most 200
  lines.
- Every command in README.md and doc/*.md runs on a fresh machine after scripts/test.sh: the ROS
  tools, and the package of each `rosrun PKG EXE` and `roslaunch PKG FILE`, come from a Debian
  package that package.xml's keys install (scripts/debian_packages.txt, with its dependencies),
  the executable or launch file exists, and this package's programs, launch files and
  run_formation.sh take the options and arguments the command gives them, and a command that
  gives a value to one of the options the program's usage line requires gives them all (prose
  about an option, `simulate --out`, gives none). A tool of the package named bare in prose
  (`simulate --scenario x.yaml`) is checked as its rosrun command.
- No file of the repository refers to a file outside it (the docs stand alone).

  test_docs.py [--gtest_output=xml:PATH]     (rosunit; --text for a plain run)
"""
import ast
import os
import re
import shutil
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import doc_commands  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
# The repository, which holds README.md, doc/ and the three packages (ROOT is variational_formation's).
REPOSITORY = os.path.dirname(ROOT)
API = os.path.join(REPOSITORY, "doc", "ros_api.md")
README_MAX_LINES = 200

# roscpp's reading calls, and the index of the name among their arguments.
CPP_READERS = {"getParam": 0, "getParamCached": 0, "param": 0, "hasParam": 0, "searchParam": 0}
# ros::param::<name>(...), qualified: a bare get() or has() is something else.
CPP_PARAM_NAMESPACE_READERS = {"get": 0, "getCached": 0, "has": 0, "param": 0, "search": 0}
# Where a reading call takes its default, when it takes one.
DEFAULT_ARGUMENT = {"param": 2, "optionalParam": 2}
PY_READERS = {"get_param": 0, "has_param": 0, "search_param": 0}
PY_DEFAULT_ARGUMENT = {"get_param": 1}
# Parameters read by a library on a node's private handle, and what in the code shows it is used.
LIBRARY_EVIDENCE = {"nodelet": "nodelet::Loader", "diagnostic_updater": "diagnostic_updater::Updater"}
TYPES = {"int", "double", "string", "bool", "double list"}


def source_files(extensions):
    for top in ("src", "include", "scripts"):
        for folder, _, names in os.walk(os.path.join(ROOT, top)):
            for name in sorted(names):
                if name.endswith(extensions):
                    yield os.path.join(folder, name)


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def relative(path):
    return os.path.relpath(path, REPOSITORY)


# --- C++ -------------------------------------------------------------------------------------

TOKEN = re.compile(r'''
    (?P<comment>//[^\n]*|/\*.*?\*/)
  | (?P<string>"(?:\\.|[^"\\\n])*")
  | (?P<char>'(?:\\.|[^'\\\n])*')
  | (?P<word>[A-Za-z_]\w*)
  | (?P<number>\d[\w.]*)
  | (?P<op>::|->|&&|\|\||[^\s\w])
''', re.S | re.X)


class Token:
    def __init__(self, kind, text, line):
        self.kind, self.text, self.line = kind, text, line

    def literal(self):
        """The value of a string literal token (no escapes are used in parameter names)."""
        return self.text[1:-1] if self.kind == "string" else None


def cpp_tokens(text):
    tokens = []
    for m in TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "comment":
            continue
        tokens.append(Token(kind, m.group(), text.count("\n", 0, m.start()) + 1))
    return tokens


def closing(tokens, i, opening, close):
    """Index of the token that closes the bracket at i."""
    depth = 0
    for k in range(i, len(tokens)):
        if tokens[k].text == opening:
            depth += 1
        elif tokens[k].text == close:
            depth -= 1
            if depth == 0:
                return k
    return len(tokens) - 1


def split_arguments(tokens, start, end):
    """The top-level comma-separated arguments of tokens[start:end]."""
    args, current, depth = [], [], 0
    for t in tokens[start:end]:
        if t.text in "([{":
            depth += 1
        elif t.text in ")]}":
            depth -= 1
        if t.text == "," and depth == 0:
            args.append(current)
            current = []
        else:
            current.append(t)
    if current:
        args.append(current)
    return args


def is_declaration(arg):
    """`const std::string& name`, `T value`: a parameter declaration, not an expression."""
    words = [t for t in arg if t.kind == "word"]
    if any(t.text == "const" for t in words):
        return True
    return any(a.kind == "word" and b.kind == "word" for a, b in zip(arg, arg[1:]))


class Read:
    def __init__(self, name, where, default=None):
        self.name, self.where, self.default = name, where, default


def calls(tokens, readers):
    """(reader, index of its '(' token) for each call of a name in readers."""
    for i, t in enumerate(tokens):
        if t.kind != "word":
            continue
        qualified_param = i >= 2 and tokens[i - 1].text == "::" and tokens[i - 2].text == "param"
        if t.text in readers:
            name = t.text
        elif qualified_param and t.text in CPP_PARAM_NAMESPACE_READERS:
            name = "param::" + t.text
        else:
            continue
        if t.text == "param" and i + 1 < len(tokens) and tokens[i + 1].text == "::":
            continue  # the namespace ros::param, not a call
        k = i + 1
        if k < len(tokens) and tokens[k].text == "<":  # template arguments
            k = closing(tokens, k, "<", ">") + 1
        if k < len(tokens) and tokens[k].text == "(":
            yield name, k


def loop_names(tokens, before, variable):
    """The names of `for (... variable : {"a", "b"})` enclosing tokens[before], if any."""
    for k in range(before - 1, max(0, before - 400), -1):
        if tokens[k].text == "for" and tokens[k + 1].text == "(":
            end = closing(tokens, k + 1, "(", ")")
            if end < before:
                header = tokens[k + 2:end]
                texts = [t.text for t in header]
                if variable in texts and ":" in texts and texts.index(":") == texts.index(variable) + 1:
                    body = header[texts.index(":") + 1:]
                    if body and body[0].text == "{" and body[-1].text == "}":
                        items = split_arguments(body, 1, len(body) - 1)
                        if items and all(len(a) == 1 and a[0].kind == "string" for a in items):
                            return [a[0].literal() for a in items]
    return None


def enclosing_function(tokens, before, variable):
    """(function name, index of `variable` among its parameters) if tokens[before] lies in a
    function that takes `variable` as a parameter: a helper forwarding the name it is given."""
    for k in range(before - 1, max(0, before - 400), -1):
        if tokens[k].text == "(" and k > 0 and tokens[k - 1].kind == "word":
            end = closing(tokens, k, "(", ")")
            if end >= before or end + 1 >= len(tokens):
                continue
            after = tokens[end + 1].text
            if after not in ("{", "const", "noexcept", "override"):
                continue
            params = split_arguments(tokens, k + 1, end)
            for index, p in enumerate(params):
                if p and p[-1].text == variable and is_declaration(p):
                    return tokens[k - 1].text, index
            return None
    return None


def searched_name(tokens, paren, word):
    """The literal name of an earlier searchParam("name", word), whose result `word` a read at
    `paren` uses (the parameter found upwards from a namespace), or None."""
    for k in range(paren - 1, max(-1, paren - 400), -1):
        if tokens[k].text == "searchParam" and tokens[k + 1].text == "(":
            args = split_arguments(tokens, k + 2, closing(tokens, k + 1, "(", ")"))
            if (len(args) == 2 and len(args[1]) == 1 and args[1][0].text == word and len(args[0]) == 1
                    and args[0][0].kind == "string"):
                return args[0][0].literal()
    return None


def cpp_reads(files, problems):
    """Every parameter read in the C++ files; problems gets each read it cannot tell."""
    parsed = {path: cpp_tokens(read(path)) for path in files}
    readers = dict(CPP_READERS)
    while True:  # helpers that forward their name argument, until no new one is found
        found = {}
        for path, tokens in parsed.items():
            for reader, paren in calls(tokens, readers):
                args = split_arguments(tokens, paren + 1, closing(tokens, paren, "(", ")"))
                index = CPP_PARAM_NAMESPACE_READERS[reader[7:]] if reader.startswith("param::") else readers[reader]
                if len(args) > index and len(args[index]) == 1 and args[index][0].kind == "word":
                    helper = enclosing_function(tokens, paren, args[index][0].text)
                    if helper and helper[0] not in readers:
                        found[helper[0]] = helper[1]
        if not found:
            break
        readers.update(found)
    reads = []
    for path, tokens in parsed.items():
        for reader, paren in calls(tokens, readers):
            args = split_arguments(tokens, paren + 1, closing(tokens, paren, "(", ")"))
            index = CPP_PARAM_NAMESPACE_READERS[reader[7:]] if reader.startswith("param::") else readers[reader]
            where = f"{relative(path)}:{tokens[paren].line}"
            if len(args) <= index:
                continue
            arg = args[index]
            if len(arg) == 1 and arg[0].kind == "string":
                default = None
                d = DEFAULT_ARGUMENT.get(reader)
                if d is not None and len(args) > d and len(args[d]) == 1 and (
                        args[d][0].kind in ("string", "number") or args[d][0].text in ("true", "false")):
                    default = args[d][0].text
                reads.append(Read(arg[0].literal().lstrip("~"), where, default))
            elif len(arg) == 1 and arg[0].kind == "word":
                names = loop_names(tokens, paren, arg[0].text)
                if names is not None:
                    reads += [Read(n.lstrip("~"), where) for n in names]
                elif searched_name(tokens, paren, arg[0].text) is not None:
                    continue  # the searchParam before it is the read, and is counted
                elif enclosing_function(tokens, paren, arg[0].text) is None:
                    problems.append(f"{where}: {reader}({arg[0].text}, ...): cannot tell which parameter it reads")
            elif not is_declaration(arg):
                text = " ".join(t.text for t in arg)
                problems.append(f"{where}: {reader}({text}, ...): cannot tell which parameter it reads")
    return reads


# --- Python and dynamic_reconfigure ------------------------------------------------------------

def python_files():
    """Python sources, with or without the .py suffix (a script named by its shebang)."""
    for path in source_files(("",)):
        if path.endswith(".py"):
            yield path
        elif "." not in os.path.basename(path):
            with open(path, "rb") as f:
                if b"python" in f.readline() and path.split(os.sep)[-2] == "scripts":
                    yield path


def python_reads(files, problems):
    reads = []
    for path in files:
        tree = ast.parse(read(path), path)
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name not in PY_READERS:
                continue
            where = f"{relative(path)}:{node.lineno}"
            arg = node.args[PY_READERS[name]] if len(node.args) > PY_READERS[name] else None
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                d = PY_DEFAULT_ARGUMENT.get(name)
                default = None
                if d is not None and len(node.args) > d and isinstance(node.args[d], ast.Constant):
                    default = repr(node.args[d].value) if isinstance(node.args[d].value, str) else str(node.args[d].value)
                reads.append(Read(arg.value.lstrip("~"), where, default))
            else:
                problems.append(f"{where}: {name}(...): cannot tell which parameter it reads")
    return reads


def reconfigure_reads():
    reads = []
    folder = os.path.join(ROOT, "cfg")
    for name in sorted(os.listdir(folder)) if os.path.isdir(folder) else ():
        path = os.path.join(folder, name)
        for m in re.finditer(r'\.add\(\s*"(\w+)"', read(path)):
            reads.append(Read(m.group(1), relative(path)))
    return reads


# --- the document ------------------------------------------------------------------------------

ENTRY = re.compile(r"^- ((?:`~\w+`(?:, )?)+)(.*)$")
SPEC = re.compile(r"^ \((?P<type>[a-z ]+), (?:(?P<required>required)|default: (?P<default>[^;]*?)"
                  r"(?:; read by (?P<library>[\w:]+))?)\): \S")


class Documented:
    def __init__(self):
        self.specs = {}      # name -> [(section, type, default or None, library or None)]
        self.references = {}  # name -> [section]: "as in ..." entries
        self.problems = []
        self.sections = []


def parse_api(text):
    doc = Documented()
    section, subsection = None, None
    for number, line in enumerate(text.splitlines(), 1):
        if line.startswith("## "):
            section, subsection = line[3:].strip(), None
            doc.sections.append(section)
            continue
        if line.startswith("### "):
            subsection = line[4:].strip()
            continue
        if subsection != "Parameters":
            continue
        m = ENTRY.match(line)
        if not m:
            continue
        names = re.findall(r"`~(\w+)`", m.group(1))
        spec = SPEC.match(m.group(2))
        if spec and len(names) == 1:
            if spec.group("type") not in TYPES:
                doc.problems.append(f"doc/ros_api.md:{number}: ~{names[0]}: unknown type '{spec.group('type')}'")
            default = None if spec.group("required") else spec.group("default")
            doc.specs.setdefault(names[0], []).append((section, spec.group("type"), default, spec.group("library")))
        elif m.group(2).startswith(": as in "):
            for n in names:
                doc.references.setdefault(n, []).append(section)
        else:
            doc.problems.append(f"doc/ros_api.md:{number}: a parameter entry must read "
                                "'- `~name` (type, required|default: value): meaning' or '- `~a`, `~b`: as in ...'")
    return doc


def same_default(code, documented):
    """The code's literal default (a C++ or Python literal) against a default in the document."""
    code = code.strip()
    if code[:1] in "\"'":
        value = code[1:-1]
        return documented == value or (value == "" and documented == '""')
    try:
        return float(code.rstrip("fFlLuU")) == float(documented)
    except ValueError:
        return code == documented


def heading_slugs(markdown):
    """GitHub's anchors for the headings of a page."""
    slugs = set()
    for line in markdown.splitlines():
        m = re.match(r"^#{1,6} (.*)$", line)
        if m:
            slug = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
            slugs.add(slug)
    return slugs


class Docs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.problems = []
        cls.reads = (cpp_reads(list(source_files((".cpp", ".hpp", ".h"))), cls.problems)
                     + python_reads(list(python_files()), cls.problems) + reconfigure_reads())
        with open(API, encoding="utf-8") as f:
            cls.doc = parse_api(f.read())

    def test_reads_are_understood(self):
        self.assertEqual(self.problems, [], "parameter reads this test cannot tell:\n" + "\n".join(self.problems))
        # The search itself works: it finds reads through each path it knows.
        wheres = {r.where.split(":")[0] for r in self.reads}
        self.assertTrue(any(w.endswith(".py") for w in wheres), "no rospy read found")
        self.assertTrue(any(w.endswith(".cfg") for w in wheres), "no dynamic_reconfigure parameter found")
        self.assertGreaterEqual(len({r.name for r in self.reads}), 20, "implausibly few parameters found")

    def test_document_is_well_formed(self):
        self.assertEqual(self.doc.problems, [], "\n".join(self.doc.problems))
        unresolved = sorted(n for n in self.doc.references if n not in self.doc.specs)
        self.assertEqual(unresolved, [], "'as in' entries whose parameter is described nowhere: " + ", ".join(unresolved))

    def test_every_read_parameter_is_documented(self):
        documented = set(self.doc.specs) | set(self.doc.references)
        missing = sorted({f"~{r.name} ({r.where})" for r in self.reads if r.name not in documented})
        self.assertEqual(missing, [], "read by the code but missing from doc/ros_api.md:\n" + "\n".join(missing))

    def test_every_documented_parameter_is_read(self):
        names_read = {r.name for r in self.reads}
        unread = []
        for name, specs in sorted(self.doc.specs.items()):
            libraries = {s[3] for s in specs if s[3]}
            for library in libraries:
                evidence = LIBRARY_EVIDENCE.get(library)
                if evidence is None:
                    unread.append(f"~{name}: read by '{library}', a library this test does not know")
                elif not any(evidence in read(p) for p in source_files((".cpp", ".hpp"))):
                    unread.append(f"~{name}: read by {library}, but no source uses {evidence}")
            if not libraries and name not in names_read:
                unread.append(f"~{name} (in {', '.join(s[0] for s in specs)})")
        self.assertEqual(unread, [], "listed in doc/ros_api.md but read by no node:\n" + "\n".join(unread))

    def test_literal_defaults_agree(self):
        wrong = []
        for r in self.reads:
            specs = self.doc.specs.get(r.name, [])
            if r.default is None or not specs:
                continue
            documented = [s[2] for s in specs if s[2] is not None]
            if r.default in ("true", "false"):
                ok = r.default in documented
            else:
                ok = any(same_default(r.default, d) for d in documented)
            if not ok:
                wrong.append(f"~{r.name}: the code's default is {r.default} ({r.where}), "
                             f"doc/ros_api.md says {', '.join(documented) or 'required'}")
        self.assertEqual(wrong, [], "\n".join(wrong))

    def test_every_node_has_a_section(self):
        nodes = set()
        for path in source_files((".cpp",)):
            text = read(path)
            if re.search(r"\bint main\(", text) and ("ros::init(" in text or "runNode<" in text):
                nodes.add(os.path.basename(path)[:-len("_main.cpp")] if path.endswith("_main.cpp") else
                          os.path.basename(path)[:-4])
        for path in [os.path.join(ROOT, "nodelet_plugins.xml")]:
            nodes |= set(re.findall(r'<class name="([\w/]+)"', read(path)))
        launchers = list(source_files((".py",)))
        for folder, _, names in os.walk(os.path.join(ROOT, "launch")):
            launchers += [os.path.join(folder, n) for n in names if n.endswith(".launch")]
        for path in launchers:
            nodes |= set(re.findall(r'pkg="variational_formation" type="([\w.]+)"', read(path)))
        self.assertIn("monitor", nodes)  # the search itself works
        headings = " ".join(self.doc.sections)
        missing = sorted(n for n in nodes if not re.search(r"(^|[\s`(])" + re.escape(n) + r"($|[\s`)])", headings))
        self.assertEqual(missing, [], "nodes without a section in doc/ros_api.md: " + ", ".join(missing))

    def test_launch_parameters_are_documented_for_their_node(self):
        # A <param> a launch file gives one of the package's nodes is a parameter of that node's
        # section (a misspelt name would be set and never read). The node's section is found by
        # its type, or by its name where the type is computed ($(eval ...): the agent).
        import xml.etree.ElementTree as ElementTree
        by_section = {}
        for name, specs in self.doc.specs.items():
            for s in specs:
                by_section.setdefault(s[0], set()).add(name)
        for name, sections in self.doc.references.items():
            for section in sections:
                by_section.setdefault(section, set()).add(name)
        wrong, checked = [], 0
        for folder, _, names in os.walk(os.path.join(ROOT, "launch")):
            for launch in sorted(n for n in names if n.endswith(".launch")):
                path = os.path.join(folder, launch)
                for node in ElementTree.parse(path).getroot().iter("node"):
                    pkg, kind = node.get("pkg", ""), node.get("type", "")
                    if pkg != "variational_formation" and "$(" not in pkg:
                        continue
                    kind = kind if "$(" not in kind else re.sub(r"_?\$\(.*", "", node.get("name", ""))
                    documented = set()
                    for section, params in by_section.items():
                        if re.sub(r"[`]", "", section).split(" ")[0] == kind:
                            documented |= params
                    for param in list(node.iter("param")) + list(node.iter("rosparam")):
                        name = param.get("name") or param.get("param")
                        checked += 1
                        if name not in documented:
                            wrong.append(f"{relative(path)}: node {node.get('name')} ({kind}) gets ~{name}, "
                                         "which its section of doc/ros_api.md does not list")
        self.assertGreater(checked, 20, "implausibly few launch parameters found")
        self.assertEqual(wrong, [], "\n".join(wrong))

    def test_launch_arguments_are_documented(self):
        text = read(API)
        sections = dict(re.findall(r"^### (\S+)\n(.*?)(?=^##)", text[text.index("\n## Launch files"):] + "\n##",
                                   re.M | re.S))
        wrong, checked = [], 0
        for folder, _, names in os.walk(os.path.join(ROOT, "launch")):
            for launch in sorted(n for n in names if n.endswith(".launch")):
                path = os.path.join(folder, launch)
                key = os.path.relpath(path, os.path.join(ROOT, "launch"))
                section = sections.get(key)
                if section is None:
                    wrong.append(f"{relative(path)}: no section '### {key}' under 'Launch files' in doc/ros_api.md")
                    continue
                args = {a.get("name"): a.get("default") for a in doc_commands.ElementTree.parse(path).getroot()
                        if a.tag == "arg" and a.get("value") is None}
                named = set(re.findall(r"`([\w/]+)`", section))
                wrong += [f"{relative(path)}: argument {a} is not in its section of doc/ros_api.md"
                          for a in sorted(set(args) - named)]
                checked += len(args)
                for row in re.findall(r"^\| (`.*?) \| (.*?) \|", section, re.M):
                    for name in re.findall(r"`(\w+)`", row[0]):
                        default = args.get(name)
                        if name not in args:
                            wrong.append(f"doc/ros_api.md, {key}: `{name}` is not an argument of {relative(path)}")
                        elif default is not None and "$(" not in default and default not in row[1].replace("`", ""):
                            wrong.append(f"doc/ros_api.md, {key}: `{name}`: the file's default is '{default}', "
                                         f"the table says '{row[1]}'")
        self.assertGreater(checked, 60, "implausibly few launch arguments found")
        self.assertEqual(wrong, [], "\n".join(wrong))

    def test_quoted_scenario_info_output_is_the_tools(self):
        import roslib.packages
        tool = roslib.packages.find_node(doc_commands.PKG, "scenario_info")
        self.assertTrue(tool, "scenario_info is not built")
        fence = re.compile(r"^```console\n(.*?)^```", re.M | re.S)
        compared = 0
        for page in doc_commands.pages():
            for block in fence.findall(read(page)):
                parts = re.split(r"^\$ ", block, flags=re.M)[1:]
                for part in parts:
                    command, *shown = part.rstrip("\n").split("\n")
                    words = command.split()
                    if words[:3] != ["rosrun", doc_commands.PKG, "scenario_info"]:
                        continue
                    result = subprocess.run(tool[:1] + words[3:], capture_output=True, text=True, timeout=60, cwd=REPOSITORY)
                    compared += 1
                    self.assertEqual(shown, (result.stderr + result.stdout).splitlines(),
                                     f"{relative(page)}: what `{command}` prints")
        self.assertGreater(compared, 0, "no quoted scenario_info output found")

    def test_one_parameter_list(self):
        pages = [os.path.join(REPOSITORY, "README.md")] + [
            os.path.join(REPOSITORY, "doc", n) for n in sorted(os.listdir(os.path.join(REPOSITORY, "doc"))) if n.endswith(".md")]
        tables = []
        for path in pages:
            if path == API:
                continue
            for number, line in enumerate(read(path).splitlines(), 1):
                if re.match(r"^\|\s*`~\w+`", line):
                    tables.append(f"{relative(path)}:{number}: {line.strip()[:60]}")
        self.assertEqual(tables, [], "parameter tables outside doc/ros_api.md (link to it instead):\n" + "\n".join(tables))

    def test_links_resolve(self):
        # Every relative link in README.md and doc/*.md names a file that exists and, with
        # #anchor, a heading of that page (GitHub's slugs): sections moved, links followed.
        pages = [os.path.join(REPOSITORY, "README.md")] + [
            os.path.join(REPOSITORY, "doc", n) for n in sorted(os.listdir(os.path.join(REPOSITORY, "doc"))) if n.endswith(".md")]
        broken = []
        for page in pages:
            text = read(page)
            for m in re.finditer(r"\]\(([^)\s]+)\)", text):
                target = m.group(1)
                if re.match(r"^[a-z]+:", target):
                    continue
                path, _, anchor = target.partition("#")
                full = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
                where = f"{relative(page)}:{text.count(chr(10), 0, m.start()) + 1}: {target}"
                if not os.path.exists(full):
                    broken.append(where + " (no such file)")
                elif anchor and full.endswith(".md") and anchor not in heading_slugs(read(full)):
                    broken.append(where + " (no such heading)")
        self.assertEqual(broken, [], "broken links:\n" + "\n".join(broken))

    def test_commands_work_on_a_fresh_machine(self):
        import roslib.packages
        import rospkg
        keys = doc_commands.declared_keys()
        installed = doc_commands.installed_closure(doc_commands.mapped_debian_packages(keys))
        programs, launches = doc_commands.own_programs(), doc_commands.own_launch_files()
        documented = set(self.doc.specs) | set(self.doc.references)
        wrong, checked, provided = [], 0, []  # provided: (where, what, path) to look up in dpkg

        tools = {name for name in programs if os.path.isfile(os.path.join(ROOT, "src", "tools", name + "_cli.cpp"))}
        for where, words in doc_commands.every_command():
            if words[0] in tools:  # a tool named bare in prose: `simulate --scenario deploy6.yaml`
                words = ["rosrun", doc_commands.PKG] + words
            tool = words[0]
            if re.fullmatch(r"(ros|catkin)\w*", tool):
                checked += 1
                if shutil.which(tool) is None:
                    wrong.append(f"{where}: {tool}: no such program")
                    continue
                provided.append((where, tool, shutil.which(tool)))
            if tool not in ("rosrun", "roslaunch"):
                continue
            positional = [w for w in words[1:] if not w.startswith("-") and ":=" not in w]
            if tool == "roslaunch" and positional and positional[0].endswith(".launch"):
                continue  # roslaunch FILE: a file of the user's
            if len(positional) < 2:
                wrong.append(f"{where}: {' '.join(words)}: expected {tool} PACKAGE NAME")
                continue
            pkg, name = positional[:2]
            command = f"{tool} {pkg} {name}"
            if pkg == doc_commands.PKG:
                self.check_own_command(where, tool, name, words, programs, launches, documented, wrong)
                continue
            if pkg not in keys:
                wrong.append(f"{where}: {command}: package.xml does not depend on {pkg}")
                continue
            try:
                found = (roslib.packages.find_node(pkg, name) if tool == "rosrun"
                         else [roslib.packages.find_resource(pkg, name)[0]])
            except (rospkg.ResourceNotFound, IndexError):
                found = []
            if not found:
                wrong.append(f"{where}: {command}: {pkg} has no {name}")
            else:
                provided.append((where, command, found[0]))
        owners = doc_commands.owners([path for _, _, path in provided])
        for where, what, path in provided:
            if owners[path] not in installed:
                wrong.append(f"{where}: {what} ({path}) comes from Debian package {owners[path]}, which "
                             "scripts/test.sh does not install (package.xml + scripts/debian_packages.txt)")
        self.assertGreater(checked, 50, "implausibly few commands found in README.md and doc/")
        self.assertEqual(wrong, [], "commands that fail on a fresh machine:\n" + "\n".join(wrong))

    def check_own_command(self, where, tool, name, words, programs, launches, documented, wrong):
        """rosrun/roslaunch of this package: the program or launch file exists, takes each --option
        given (a string literal of its sources), each launch argument name:=value (run_formation.sh:
        of the launch file it runs) and each private parameter _name:=value (doc/ros_api.md)."""
        command = f"{tool} {doc_commands.PKG} {name}"
        if tool == "roslaunch":
            if name not in launches:
                wrong.append(f"{where}: {command}: no such launch file in launch/")
                return
            arguments = doc_commands.launch_args(launches[name])
        elif name not in programs:
            wrong.append(f"{where}: {command}: neither in scripts/ nor built by cmake/*.cmake")
            return
        elif name == "run_formation.sh":
            launch = "robots.launch" if "launch:=robots" in words else "formation.launch"
            arguments = doc_commands.launch_args(launches[launch]) | {"launch"}
        else:
            arguments = None
        sources = "".join(read(p) for p in doc_commands.program_sources(name, programs)) if tool == "rosrun" else ""
        given = {w.split("=", 1)[0] for w in words[3:]}
        required = doc_commands.required_options(name, sources) if tool == "rosrun" else set()
        # A run gives a required option a value; prose about options (`simulate --out`) does not.
        valued = {w for w, after in zip(words[3:], words[4:]) if w in required and not after.startswith("-")}
        if valued and not given & {"--help", "-h"}:
            for option in sorted(required - given):
                wrong.append(f"{where}: {command}: the required option {option} is missing")
        for word in words[3:]:
            option, assigned = word.split("=", 1)[0], word.split(":=", 1)[0]
            if option.startswith("--") and f'"{option}"' not in sources and f"'{option}'" not in sources:
                wrong.append(f"{where}: {command}: no option {option}")
            elif ":=" in word and arguments is not None and assigned not in arguments:
                wrong.append(f"{where}: {command}: no argument {assigned}")
            elif ":=" in word and arguments is None and re.fullmatch(r"_[a-z]\w*", assigned) and (
                    assigned[1:] not in documented):
                wrong.append(f"{where}: {command}: no parameter ~{assigned[1:]} in doc/ros_api.md")

    def test_no_reference_outside_the_repository(self):
        # Every page named anywhere in the repository is one of its own, and no path climbs out
        # of it (the design notes and style guide of the workplace are not shipped).
        pages, outside = set(), []
        for _, dirs, names in os.walk(REPOSITORY):
            dirs[:] = [d for d in dirs if not d.startswith(".") and d not in ("output", "build", "devel")]
            pages |= {n for n in names if n.endswith(".md")}
        for folder, dirs, names in os.walk(REPOSITORY):
            dirs[:] = [d for d in dirs if not d.startswith(".") and d not in ("output", "build", "devel")]
            for name in names:
                path = os.path.join(folder, name)
                try:
                    text = read(path)
                except (UnicodeDecodeError, OSError):
                    continue  # a picture
                for number, line in enumerate(text.splitlines(), 1):
                    named = {m for m in re.findall(r"([\w-]+\.md)\b", line) if m not in pages}
                    climbs = re.findall(r"\.\./shared\b|/work/(?:shared)\b", line)
                    if named or climbs:
                        outside.append(f"{relative(path)}:{number}: {', '.join(sorted(named) + climbs)}")
        self.assertEqual(outside, [], "references to files outside the repository:\n" + "\n".join(outside))

    def test_readme_is_a_front_door(self):
        with open(os.path.join(REPOSITORY, "README.md"), encoding="utf-8") as f:
            lines = f.read().splitlines()
        self.assertLessEqual(len(lines), README_MAX_LINES,
                             f"README.md has {len(lines)} lines; move details to doc/ (at most {README_MAX_LINES})")
        self.assertIn("./scripts/demo.sh", "\n".join(lines[:8]))
        self.assertIn("./scripts/test.sh", "\n".join(lines[:8]))


if __name__ == "__main__":
    if "--text" in sys.argv:
        unittest.main(argv=[sys.argv[0], "-v"])
    import rosunit
    rosunit.unitrun("variational_formation", "docs", Docs)
