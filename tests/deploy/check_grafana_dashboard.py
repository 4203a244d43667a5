#!/usr/bin/env python3
"""Deploy.GrafanaDashboard: deploy/grafana/skyfarm-dashboard.json is a Grafana
dashboard whose queries name only metrics skyfarm-server exports.

usage: check_grafana_dashboard.py --source DIR --server BIN

What is checked (every failure is printed; exit 1 if any): the file is JSON
with a schemaVersion of at least 36, a uid and a title; a templating variable
of type "datasource" for Prometheus, and every panel and target uses it
(`${name}`), never a fixed datasource uid; panel ids are unique; every target
has an expr; every skyfarm_* name in an expr is one the server's /metrics
lists (a histogram's name with _bucket, _sum or _count counts as its own),
read from a short run of the built server on loopback; and the panels the
operations page promises are there (queue, workers, samples/s, unit and job
durations, HTTP latency, error rates, disk).
"""
import argparse
import json
import os
import re
import sys
import urllib.request

from idle_server import idle_server

errors = []


def error(text):
    errors.append(text)


def scrape(server_binary):
    """The /metrics text of a fresh server without workers."""
    with idle_server(server_binary) as url:
        with urllib.request.urlopen(url + "/metrics", timeout=5) as r:
            return r.read().decode()


def exported_names(text):
    """Every metric name /metrics shows, with a histogram's series names."""
    names, histograms = set(), set()
    for line in text.splitlines():
        m = re.match(r"# TYPE (\S+) (\S+)", line)
        if m:
            names.add(m.group(1))
            if m.group(2) == "histogram":
                histograms.add(m.group(1))
            continue
        m = re.match(r"([a-zA-Z_:][a-zA-Z0-9_:]*)", line)
        if m:
            names.add(m.group(1))
    for h in histograms:
        names.update({h + "_bucket", h + "_sum", h + "_count"})
    return names


def panels_of(dashboard):
    for p in dashboard.get("panels", []):
        yield p
        yield from p.get("panels", [])  # a collapsed row keeps its panels inside


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", required=True)
    ap.add_argument("--server", required=True)
    a = ap.parse_args()
    path = os.path.join(a.source, "deploy", "grafana", "skyfarm-dashboard.json")
    with open(path) as f:
        dashboard = json.load(f)

    if not isinstance(dashboard.get("schemaVersion"), int) or dashboard["schemaVersion"] < 36:
        error(f"schemaVersion {dashboard.get('schemaVersion')!r}: want 36 or later")
    for key in ("uid", "title"):
        if not dashboard.get(key):
            error(f"no {key}")
    variables = [v for v in dashboard.get("templating", {}).get("list", [])
                 if v.get("type") == "datasource" and v.get("query") == "prometheus"]
    if len(variables) != 1:
        error("want one templating variable of type datasource for prometheus")
        ds_ref = None
    else:
        ds_ref = "${" + variables[0]["name"] + "}"

    metrics = exported_names(scrape(os.path.abspath(a.server)))
    ids, exprs = set(), []
    for p in panels_of(dashboard):
        where = f"panel {p.get('title')!r}"
        if p.get("id") in ids:
            error(f"{where}: id {p.get('id')} twice")
        ids.add(p.get("id"))
        if p.get("type") == "row":
            continue
        if p.get("datasource", {}).get("uid") != ds_ref:
            error(f"{where}: datasource {p.get('datasource')!r} is not the variable {ds_ref}")
        if not p.get("targets"):
            error(f"{where}: no targets")
        for t in p.get("targets", []):
            expr = t.get("expr", "")
            if not expr:
                error(f"{where}: a target without expr")
            if t.get("datasource", {}).get("uid") != ds_ref:
                error(f"{where}: a target's datasource is not the variable {ds_ref}")
            exprs.append((p.get("title", ""), expr))
            for name in sorted(set(re.findall(r"\bskyfarm_[a-zA-Z0-9_]+", expr)) - metrics):
                error(f"{where}: {name} is not a metric skyfarm-server exports on /metrics")

    # The panels an operator is promised (deploy/README.md, Monitoring).
    promised = {
        "queue units": r"skyfarm_queue_units\b",
        "units in flight": r"skyfarm_units_in_flight\b",
        "workers": r"skyfarm_workers\b",
        "samples/s": r"rate\(skyfarm_samples_total\[",
        "unit duration p50": r"histogram_quantile\(0\.5, .*skyfarm_unit_duration_seconds_bucket",
        "unit duration p95": r"histogram_quantile\(0\.95, .*skyfarm_unit_duration_seconds_bucket",
        "job duration p95": r"histogram_quantile\(0\.95, .*skyfarm_job_duration_seconds_bucket",
        "HTTP latency p95 by route": r"histogram_quantile\(0\.95, sum by \(le, route\).*skyfarm_http_request_duration_seconds_bucket",
        "unit failures": r"skyfarm_unit_failures_total",
        "requeues": r"skyfarm_unit_requeues_total",
        "auth failures": r"skyfarm_worker_auth_failures_total",
        "disk used": r"skyfarm_disk_used_bytes",
        "disk budget": r"skyfarm_disk_budget_bytes",
    }
    for what, pattern in promised.items():
        if not any(re.search(pattern, e) for _, e in exprs):
            error(f"no query shows {what} (/{pattern}/)")

    for e in errors:
        print("error:", e)
    print(f"{len(exprs)} queries, {len(errors)} error(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
