"""The shell commands of README.md and doc/*.md, and what a fresh machine has to run them with:
test_docs.py checks each against what scripts/test.sh installs (the Debian packages that
scripts/debian_packages.txt maps package.xml's keys to, with their dependencies) and against
this package's own programs, launch files and their arguments."""
import glob
import os
import re
import shlex
import subprocess
import xml.etree.ElementTree as ElementTree

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
# The repository, which holds README.md, doc/ and the three packages (ROOT is variational_formation's).
REPOSITORY = os.path.dirname(ROOT)
PKG = "variational_formation"
SHELL_BLOCKS = {"", "bash", "sh", "shell", "console"}


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def pages():
    return [os.path.join(REPOSITORY, "README.md")] + sorted(glob.glob(os.path.join(REPOSITORY, "doc", "*.md")))


def snippets(text):
    """(line number, shell text) of each fenced shell block's command lines and each inline code
    span. In a block with `$ ` prompts only the prompted lines are commands (the rest is output)."""
    found = []
    fence = re.compile(r"^```(\w*)\n(.*?)^```", re.M | re.S)
    for m in fence.finditer(text):
        if m.group(1) not in SHELL_BLOCKS:
            continue
        first = text.count("\n", 0, m.start()) + 2
        lines = m.group(2).replace("\\\n", " ").splitlines()
        prompted = any(line.startswith("$ ") for line in lines)
        for k, line in enumerate(lines):
            if prompted and not line.startswith("$ "):
                continue
            found.append((first + k, line[2:] if prompted else line))
    prose = fence.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    for m in re.finditer(r"`([^`\n]+)`", prose):
        if " " in m.group(1).strip():  # one word is a name, not a command
            found.append((prose.count("\n", 0, m.start()) + 1, m.group(1)))
    return found


def commands(shell):
    """The simple commands of a line of shell, each a list of words without leading variable
    assignments and sudo (split at ;, &&, ||, | and &; comments dropped)."""
    lexer = shlex.shlex(shell, posix=True, punctuation_chars=";&|")
    lexer.whitespace_split = True
    try:
        words = list(lexer)
    except ValueError:  # an unbalanced quote in prose
        words = shell.split()
    result, current = [], []
    for word in words + [";"]:
        if word and set(word) <= set(";&|"):
            if current:
                result.append(current)
            current = []
        elif not current and (re.fullmatch(r"\w+=\S*", word) or word == "sudo"):
            continue
        else:
            current.append(word)
    return result


def every_command():
    """(page:line, words) of every command in README.md and doc/*.md."""
    for page in pages():
        for line, shell in snippets(read(page)):
            for words in commands(shell):
                yield f"{os.path.relpath(page, REPOSITORY)}:{line}", words


# --- what the package has ----------------------------------------------------------------------

def own_programs():
    """{name: [source files]}: the scripts and the programs cmake/*.cmake builds."""
    programs = {os.path.basename(p): [p] for p in glob.glob(os.path.join(ROOT, "scripts", "*")) if os.path.isfile(p)}
    for path in glob.glob(os.path.join(ROOT, "cmake", "*.cmake")):
        text = read(path)
        loops = {m[1]: m[2].split() for m in re.finditer(r"foreach\((\w+)\s+([^)]*)\)", text)}
        # add_executable, and vf_add_tool (cmake/functions.cmake), which wraps it for the CLIs.
        for name, files in re.findall(r"(?:add_executable|vf_add_tool)\(\s*(\S+)\s+([^)]*)\)", text):
            var = re.fullmatch(r"\$\{(\w+)\}", name)
            for each in loops.get(var[1], []) if var else [name]:
                programs[each] = [os.path.join(ROOT, f.replace("${" + var[1] + "}", each) if var else f)
                                  for f in files.split() if f.endswith(".cpp")]
    return programs


def program_sources(name, programs):
    """The files whose string literals hold a program's options: its own sources, and for a tool
    src/tools/<name>_cli.cpp, where its arguments are parsed."""
    files = list(programs.get(name, []))
    cli = os.path.join(ROOT, "src", "tools", name + "_cli.cpp")
    return files + ([cli] if os.path.isfile(cli) else [])


def required_options(name, sources):
    """The options every form of a program's usage line requires (those outside [...]), from the
    usage text in its sources: `usage: NAME ...` and each further form `   NAME ...`."""
    forms = re.findall(r'["\']\s*(?:usage:\s*)?' + re.escape(name) + r' ([^"\'\\]*)', sources)
    required = None
    for form in forms:
        bare = form
        while re.search(r"\[[^\[\]]*\]", bare):
            bare = re.sub(r"\[[^\[\]]*\]", "", bare)
        options = set(re.findall(r"--[\w-]+", bare))
        required = options if required is None else required & options
    return required or set()


def own_launch_files():
    return {os.path.basename(p): p for p in glob.glob(os.path.join(ROOT, "launch", "**", "*.launch"), recursive=True)}


def launch_args(path):
    return {a.get("name") for a in ElementTree.parse(path).getroot().iter("arg")}


# --- what scripts/test.sh installs ---------------------------------------------------------------

def declared_keys():
    """The dependency keys of the repository's three packages."""
    return {e.text.strip() for xml in glob.glob(os.path.join(REPOSITORY, "*", "package.xml"))
            for e in ElementTree.parse(xml).getroot() if e.tag.endswith("depend")}


def mapped_debian_packages(keys):
    packages = set()
    for line in read(os.path.join(ROOT, "scripts", "debian_packages.txt")).splitlines():
        key, _, names = line.partition(":")
        if not line.startswith("#") and key in keys:
            packages |= set(names.split())
    return packages


def installed_closure(roots):
    """The installed Debian packages `roots` bring, with everything they depend on (Depends and
    Pre-Depends, through virtual packages; of alternatives the installed ones)."""
    listing = subprocess.run(["dpkg-query", "-W", "-f=${db:Status-Abbrev}\t${Package}\t${Provides}\t"
                              "${Depends}, ${Pre-Depends}\n"], capture_output=True, text=True).stdout
    depends, provided = {}, {}
    for row in listing.splitlines():
        status, name, provides, deps = (row.split("\t") + ["", "", "", ""])[:4]
        if not status.startswith("ii"):
            continue
        depends[name] = deps
        for virtual in provides.split(","):
            if virtual.strip():
                provided.setdefault(re.sub(r"\s*\(.*", "", virtual.strip()), set()).add(name)
    seen, queue = set(), [p for p in roots if p in depends]
    while queue:
        name = queue.pop()
        if name in seen:
            continue
        seen.add(name)
        for group in depends[name].split(","):
            for alternative in group.split("|"):
                bare = re.sub(r"\s*\(.*|:\w+$", "", alternative.strip())
                queue += [p for p in ({bare} & set(depends)) | provided.get(bare, set()) if p not in seen]
    return seen


def owners(paths):
    """{path: the Debian package that installed it} (one dpkg-query for all: each takes a second)."""
    real = {p: os.path.realpath(p) for p in paths}
    result = subprocess.run(["dpkg-query", "-S"] + sorted(set(real.values())), capture_output=True, text=True)
    found = {}
    for line in result.stdout.splitlines():
        package, _, path = line.partition(": ")
        if not package.startswith("diversion "):
            found[path.strip()] = package.split(":")[0].split(",")[0].strip()
    return {p: found.get(r) for p, r in real.items()}
