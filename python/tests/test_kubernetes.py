# The Kubernetes cluster spec of dmi_sweep.kubernetes, offline (no Kubernetes here): the scheduler's
# and the workers' arguments parsed by distributed's own command lines (valid options; one thread per
# worker), the scheduler's environment read by Dask's configuration (worker-saturation 1.0), the
# Service selecting the scheduler pod's labels and naming its ports, a YAML round trip as kubectl gets
# it; bad inputs refused.  Against dask-kubernetes' own make_cluster_spec.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dask
import pytest
import yaml

from dmi_sweep.kubernetes import cluster_spec


def test_spec_parsed_by_dask_and_consistent():
    from distributed.cli.dask_scheduler import main as scheduler_main
    from distributed.cli.dask_worker import main as worker_main
    spec = cluster_spec("sweep", "registry.example/dmi:1.1", 16, memory="3Gi", cpu="1")
    assert spec["apiVersion"] == "kubernetes.dask.org/v1" and spec["kind"] == "DaskCluster"
    assert spec["metadata"]["name"] == "sweep" and spec["spec"]["worker"]["replicas"] == 16
    (worker,) = spec["spec"]["worker"]["spec"]["containers"]
    (scheduler,) = spec["spec"]["scheduler"]["spec"]["containers"]
    assert worker["image"] == scheduler["image"] == "registry.example/dmi:1.1"
    assert worker["resources"]["requests"] == worker["resources"]["limits"] == {"cpu": "1", "memory": "3Gi"}

    assert worker["args"][:2] == ["dask", "worker"] and scheduler["args"][:2] == ["dask", "scheduler"]
    w = worker_main.make_context("dask worker", ["tcp://sweep-scheduler:8786", *worker["args"][2:]]).params
    assert w["nthreads"] == 1 and w["n_workers"] == "1" and w["memory_limit"] == "auto"
    s = scheduler_main.make_context("dask scheduler", scheduler["args"][2:]).params
    assert int(s["port"]) == 8786 and s["host"] == "0.0.0.0"

    env = {e["name"]: e["value"] for e in scheduler["env"]}
    config = dask.config.collect(paths=[], env=env)
    assert dask.config.get("distributed.scheduler.worker-saturation", config=config) == 1.0

    service = spec["spec"]["scheduler"]["service"]
    assert service["selector"] == {"dask.org/cluster-name": "sweep", "dask.org/component": "scheduler"}
    names = {p["name"]: p["containerPort"] for p in scheduler["ports"]}
    assert {p["targetPort"] for p in service["ports"]} <= set(names)
    assert {p["port"] for p in service["ports"]} == {names["tcp-comm"], names["http-dashboard"]} == {8786, 8787}
    assert yaml.safe_load(yaml.safe_dump(spec)) == spec


def test_same_shape_as_dask_kubernetes():
    """Against dask-kubernetes' own make_cluster_spec (pinned in scripts/requirements.txt: a
    missing package fails here, it does not skip): the same resource, the same scheduler Service
    and ports, the same layout."""
    from dask_kubernetes.operator import make_cluster_spec
    theirs = make_cluster_spec("sweep", image="img", n_workers=3)
    ours = cluster_spec("sweep", "img", 3)
    assert ours.keys() == theirs.keys()
    for key in ("apiVersion", "kind"):
        assert ours[key] == theirs[key]
    assert ours["metadata"]["name"] == theirs["metadata"]["name"]
    # theirs also writes idleTimeout: 0, the DaskCluster resource's default (no idle shutdown),
    # which ours leaves out
    assert theirs["spec"].get("idleTimeout") == 0
    assert ours["spec"].keys() == theirs["spec"].keys() - {"idleTimeout"}
    assert ours["spec"]["scheduler"].keys() == theirs["spec"]["scheduler"].keys()
    assert ours["spec"]["worker"].keys() == theirs["spec"]["worker"].keys()
    assert ours["spec"]["worker"]["replicas"] == theirs["spec"]["worker"]["replicas"] == 3
    assert ours["spec"]["scheduler"]["service"] == theirs["spec"]["scheduler"]["service"]
    (o,), (t,) = (x["spec"]["scheduler"]["spec"]["containers"] for x in (ours, theirs))
    assert o["ports"] == t["ports"]


@pytest.mark.parametrize("kw, message", [
    ({"name": "Sweep"}, "is not a Kubernetes name"),
    ({"workers": 0}, "workers = 0 is not an integer >= 1"),
    ({"memory": "3 GB"}, "memory = '3 GB' is not a Kubernetes quantity"),
    ({"cpu": "one"}, "cpu = 'one' is not a Kubernetes quantity"),
])
def test_bad_inputs(kw, message):
    args = {"name": "sweep", "image": "img", "workers": 2, **kw}
    with pytest.raises(ValueError, match=message):
        cluster_spec(**args)
