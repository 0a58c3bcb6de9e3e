# A Dask cluster for dmi-sweep on Kubernetes: the DaskCluster resource of the Dask Kubernetes
# operator (dask-kubernetes' KubeCluster(custom_cluster_spec=...), or kubectl apply), with the
# settings a sweep needs: one single-threaded worker per pod, the scheduler running one task per
# worker at a time, requests equal to limits.  Built here without dask-kubernetes (tested offline);
# see docs/kubernetes.md.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import re
from typing import Any

SCHEDULER_PORT, DASHBOARD_PORT = 8786, 8787
# a Kubernetes object name (RFC 1123 label: the scheduler's Service is named <name>-scheduler)
NAME = re.compile(r"[a-z0-9]([-a-z0-9]{0,40}[a-z0-9])?")
QUANTITY = re.compile(r"[0-9]+(\.[0-9]+)?(m|k|M|G|T|Ki|Mi|Gi|Ti)?")


def cluster_spec(name: str, image: str, workers: int, memory: str = "2Gi", cpu: str = "1") -> dict[str, Any]:
    """The DaskCluster resource (``kubernetes.dask.org/v1``) of a sweep's cluster.

    Workers: ``dask worker --nthreads 1``, their memory limit the pod's. Scheduler:
    worker-saturation 1.0 (a dying worker takes no queued chunk with it), reached in the cluster at
    ``tcp://<name>-scheduler:8786``.

    Parameters
    ----------
    name : str
        The cluster's name: a Kubernetes name (lower-case letters, digits and '-', at most 42
        characters).
    image : str
        The container image of the scheduler and workers; it must hold Python with fmpy, numpy and
        distributed at the client's versions.
    workers : int
        The number of worker pods, >= 1.
    memory, cpu : str
        Each worker pod's memory and CPU, Kubernetes quantities (requests = limits), e.g. ``"2Gi"``,
        ``"500m"``.

    Returns
    -------
    dict
        The resource, ready for ``kubectl apply`` (as JSON or YAML).

    Raises
    ------
    ValueError
        For a bad name, worker count or quantity.
    """
    if not NAME.fullmatch(name):
        raise ValueError(f"name {name!r} is not a Kubernetes name (lower-case letters, digits and '-', "
                         "at most 42 characters)")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers = {workers!r} is not an integer >= 1")
    for what, q in (("memory", memory), ("cpu", cpu)):
        if not isinstance(q, str) or not QUANTITY.fullmatch(q):
            raise ValueError(f"{what} = {q!r} is not a Kubernetes quantity (such as 2Gi, 500m)")
    resources = {"requests": {"cpu": cpu, "memory": memory}, "limits": {"cpu": cpu, "memory": memory}}
    worker = {
        "name": "worker", "image": image, "resources": resources,
        "args": ["dask", "worker", "--name", "$(DASK_WORKER_NAME)", "--nthreads", "1", "--nworkers", "1",
                 "--memory-limit", "auto", "--dashboard-address", "8788"],
        "ports": [{"name": "http-dashboard", "containerPort": 8788, "protocol": "TCP"}],
    }
    scheduler = {
        "name": "scheduler", "image": image,
        "args": ["dask", "scheduler", "--host", "0.0.0.0", "--port", str(SCHEDULER_PORT),
                 "--dashboard-address", f":{DASHBOARD_PORT}"],
        "env": [{"name": "DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION", "value": "1.0"}],
        "ports": [{"name": "tcp-comm", "containerPort": SCHEDULER_PORT, "protocol": "TCP"},
                  {"name": "http-dashboard", "containerPort": DASHBOARD_PORT, "protocol": "TCP"}],
        "readinessProbe": {"httpGet": {"port": "http-dashboard", "path": "/health"}, "periodSeconds": 1},
    }
    service = {
        "type": "ClusterIP",
        "selector": {"dask.org/cluster-name": name, "dask.org/component": "scheduler"},
        "ports": [{"name": "tcp-comm", "protocol": "TCP", "port": SCHEDULER_PORT, "targetPort": "tcp-comm"},
                  {"name": "http-dashboard", "protocol": "TCP", "port": DASHBOARD_PORT,
                   "targetPort": "http-dashboard"}],
    }
    return {"apiVersion": "kubernetes.dask.org/v1", "kind": "DaskCluster", "metadata": {"name": name},
            "spec": {"worker": {"replicas": workers, "spec": {"containers": [worker]}},
                     "scheduler": {"spec": {"containers": [scheduler]}, "service": service}}}
