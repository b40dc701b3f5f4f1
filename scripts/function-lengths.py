#!/usr/bin/env python3
"""Lengths of the C++ function bodies of a tree, longest first.

    scripts/function-lengths.py [ROOT] [LIMIT]   # list functions longer than LIMIT lines (100)

A definition starts at a line indented 0 or 2 spaces that looks like `type name(` and whose
statement (within 8 lines) opens a brace before a ';'; its length runs from that line to the
matching closing brace (braces counted outside one-line string and character literals and
line comments, which is enough for this code base: no braces in literals that span lines).
build/ and .git/ are skipped. Exit 1 if any is too long.
"""
import os
import re
import sys
# Function lengths by brace matching: a definition starts at a line at indentation 0 or 2 that
# looks like `type name(` and whose statement (up to 6 lines) ends in '{' rather than ';'.
sig=re.compile(r'^(  )?(?!(if|for|while|switch|return|else|namespace|struct|class|enum|using|case|do)\b)[A-Za-z_][\w:<>,\*&\s]*?[\w:~\]]+\s*\(')
literal=re.compile(r'"(?:[^"\\]|\\.)*"|\'(?:[^\'\\]|\\.)*\'|//.*$')


def code_only(line):
    """The line without its string and character literals and its // comment."""
    return literal.sub('""', line)


res=[]
root_dir = sys.argv[1] if len(sys.argv) > 1 else "."
for root,_,files in os.walk(root_dir):
    if '/build' in root or '/.git' in root: continue
    for f in files:
        if not f.endswith(('.cpp','.hpp')): continue
        p=os.path.join(root,f); lines=open(p,errors='replace').read().split('\n')
        i=0
        while i<len(lines):
            l=lines[i]
            if sig.match(l) and not l.rstrip().endswith(';'):
                j=i; ok=False
                while j<min(len(lines),i+8):
                    t=lines[j].rstrip()
                    if t.endswith(';') and '{' not in t: break
                    if '{' in t: ok=True; break
                    j+=1
                if ok:
                    depth=0; k=j; started=False
                    while k<len(lines):
                        for ch in code_only(lines[k]):
                            if ch=='{': depth+=1; started=True
                            elif ch=='}': depth-=1
                        if started and depth<=0: break
                        k+=1
                    res.append((k-i+1,p,i+1,l.strip()[:70])); i=k+1; continue
            i+=1
lim=int(sys.argv[2]) if len(sys.argv)>2 else 100
for n,p,ln,s in sorted(res,reverse=True):
    if n>lim: print(n,os.path.relpath(p, root_dir)+':'+str(ln),s)
print("functions:", len(res), "longest:", max(res)[0] if res else 0)
sys.exit(1 if any(n > lim for n, *_ in res) else 0)
