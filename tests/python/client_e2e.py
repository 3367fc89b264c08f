#!/usr/bin/env python3
"""End to end through the Python client that openapi-python-client generates
from openapi.yaml, and only through it: create the Surveyor ROV, a campaign,
its plan; fly four planned dynamic experiments and the validation run
through a small simulator (decoupled first-order DOFs, as web/tests/sim.mjs)
and upload them; identify (a λ-filter job, polled to success); fetch the
model with its ZOH matrices; export it as JSON and NumPy .npz and check both
against the model. Any error response, unexpected status or mismatch stops
it with a message and exit status 1.

Usage: client_e2e.py BASE_URL   (run by `make client-e2e`, which generates
and installs the client `seatrial_client` and starts the real binary)
"""

import io
import json
import pathlib
import sys
import time

import numpy as np
from seatrial_client import Client
from seatrial_client.api.jobs import get_job, submit_job
from seatrial_client.api.models import export_model, get_model, list_models
from seatrial_client.api.planning import create_campaign, create_vessel, generate_plan
from seatrial_client.api.runs import list_runs, upload_run
from seatrial_client.api.service import health
from seatrial_client.models import (
    CampaignRevision,
    ErrorBody,
    ExportFormat,
    Job,
    JobRequest,
    ModelView,
    NewCampaign,
    PlanRevision,
    Run,
    RunMeta,
    UploadForm,
    Vessel,
    VesselProfile,
)
from seatrial_client.types import File

KN = 1852 / 3600
TC = [4.0, 3.0, 3.0, 1.5, 1.5, 2.0]  # time constants (s)
D = [2000.0, 4000.0, 4000.0, 3000.0, 3000.0, 3000.0]  # damping per DOF
AMP = [300.0, 600.0, 600.0, 300.0, 300.0, 300.0]  # force amplitudes
COLUMNS = ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N",
           "u", "v", "w", "p", "q", "r", "x", "y", "z", "phi", "theta", "psi"]
steps = 0


def ok(what):
    global steps
    steps += 1
    print(f"ok   {what}", flush=True)


def fail(what):
    print(f"FAIL {what}", flush=True)
    print(f"{steps} passed, 1 failed")
    sys.exit(1)


def expect(response, status, cls, what):
    """The parsed body of a response with this status and type, else fail."""
    if response.status_code != status or not isinstance(response.parsed, cls):
        body = response.parsed.to_dict() if isinstance(response.parsed, ErrorBody) else response.content[:500]
        fail(f"{what}: HTTP {int(response.status_code)} {body!r} (expected {status} {cls.__name__})")
    ok(what)
    return response.parsed


def simulate(seed, fs, duration, surge, force=None):
    """τ, ν, η of decoupled first-order DOFs T·ν̇ = −ν + τ/d under held
    random-binary forces (clock 2 s) plus the surge trim force, small noise."""
    rng = np.random.default_rng(seed)
    n, h = int(duration * fs), 1.0 / fs
    t = np.arange(n) * h
    hold = int(round(2.0 * fs))
    tau, nu, eta = np.zeros((n, 6)), np.zeros((n, 6)), np.zeros((n, 6))
    for i in range(6):
        a = np.exp(-h / TC[i])
        levels = np.where(rng.random(n // hold + 1) < 0.5, -AMP[i], AMP[i])
        v, pos = (surge if i == 0 else 0.0), (20.0 if i == 2 else 0.0)
        for k in range(n):
            f = (surge * D[0] if i == 0 else 0.0) + levels[k // hold]
            if force is not None and i == 0:
                f = force(k)
            tau[k, i] = f
            nu[k, i] = v + 1e-4 * rng.standard_normal()
            eta[k, i] = pos + 1e-4 * rng.standard_normal()
            v = a * v + (1 - a) * f / D[i]
            pos += v * h
    eta[:, 2] += 3 * np.sin(t / 40) + 1.5 * np.sin(t / 13)
    lines = [",".join(["t"] + COLUMNS)]
    for k in range(n):
        lines.append(",".join(repr(float(x)) for x in [t[k], *tau[k], *nu[k], *eta[k]]))
    return "\n".join(lines) + "\n"


def upload(client, cid, experiment, csv):
    body = UploadForm(
        meta=RunMeta.from_dict({"experiment_id": experiment.id, "name": experiment.code}),
        file=File(payload=io.BytesIO(csv.encode()), file_name=f"{experiment.code}.csv", mime_type="text/csv"),
    )
    run = expect(upload_run.sync_detailed(cid, client=client, body=body), 201, Run, f"upload {experiment.code}")
    if str(run.status) != "accepted":
        fail(f"{experiment.code} was {run.status}")
    return run


def main():
    base = sys.argv[1]
    client = Client(base_url=base, raise_on_unexpected_status=True, timeout=120.0)
    expect(health.sync_detailed(client=client), 200, object, "health")

    profile = json.loads((pathlib.Path(__file__).parent / "surveyor_rov.json").read_text())
    profile["name"] = "Surveyor ROV (generated client)"
    vessel = expect(create_vessel.sync_detailed(client=client, body=VesselProfile.from_dict(profile)),
                    201, Vessel, "create vessel")
    spec = {"vessel_id": vessel.id, "name": "Generated-client e2e", "grid": {"unit": "kn", "speeds": [1, 2]},
            "families": ["dynamic", "validation"], "seed": 11}
    campaign = expect(create_campaign.sync_detailed(client=client, body=NewCampaign.from_dict(spec)),
                      201, object, "create campaign")
    cid = campaign.id
    # An empty revision: the generated code sends an absent optional body as
    # the JSON of its UNSET marker, so the body is always given.
    plan = expect(generate_plan.sync_detailed(cid, client=client, body=CampaignRevision.from_dict({})),
                  201, PlanRevision, "plan")
    by_code = {e.code: e for e in plan.experiments}

    seed = 100
    for code in ["DYN-1kn-surge-r1", "DYN-1kn-sway-r1", "DYN-2kn-surge-r1", "DYN-2kn-sway-r1"]:
        if code not in by_code:
            fail(f"{code} not planned: {sorted(by_code)}")
        seed += 1
        e = by_code[code]
        upload(client, cid, e, simulate(seed, 10, 180, e.grid_speed_mps))
    validation = next((e for e in plan.experiments if str(e.family) == "validation"), None)
    if validation is None:
        fail("no validation experiment planned")
    n = 3600
    square = lambda k: (1 if k < n / 2 else 2) * KN * D[0] + (300 if (k // 20 * 7919) % 2 else -300)  # noqa: E731
    upload(client, cid, validation, simulate(7, 10, 360, 1 * KN, force=square))
    runs = expect(list_runs.sync_detailed(cid, client=client), 200, list, "list runs")
    if len(runs) != 5:
        fail(f"{len(runs)} runs listed, expected 5")

    request = JobRequest.from_dict({"kind": "identify", "campaign_id": cid, "method": "lambda_kf",
                                    "settings": {"structure": "diagonal"}})
    job = expect(submit_job.sync_detailed(client=client, body=request), 202, Job, "submit identify job")
    deadline = time.monotonic() + 300
    while str(job.state) in ("queued", "running"):
        if time.monotonic() > deadline:
            fail(f"job {job.id} still {job.state} after 300 s")
        time.sleep(0.5)
        job = get_job.sync_detailed(job.id, client=client).parsed
        if not isinstance(job, Job):
            fail(f"polling the job: {job}")
    if str(job.state) != "succeeded":
        fail(f"job {job.state}: {job.error.to_dict() if job.error else ''}")
    ok(f"identify job succeeded ({job.stage})")
    mid = job.result.to_dict()["model_id"]

    models = expect(list_models.sync_detailed(client=client, campaign_id=cid), 200, list, "list models")
    if [m.id for m in models] != [mid]:
        fail(f"models of the campaign: {[m.id for m in models]}")
    view = expect(get_model.sync_detailed(mid, client=client, h=0.05), 200, ModelView, "fetch model with ?h=0.05")
    doc = view.document.to_dict()
    if doc["kind"] != "lpv" or len(doc["lpv"]["points"]) != 2:
        fail(f"model kind {doc['kind']}, {len(doc.get('lpv', {}).get('points', []))} grid points")
    if len(view.discrete.points) != 2:
        fail("no ZOH matrices")

    exported = expect(export_model.sync_detailed(mid, client=client, format_=ExportFormat.JSON), 200, File,
                      "export json")
    as_json = json.loads(exported.payload.read())
    if as_json["model"]["id"] != mid or as_json["document"] != doc:
        fail("the JSON export is not the model")
    ok("JSON export equals the model")

    npz = expect(export_model.sync_detailed(mid, client=client, format_=ExportFormat.NPZ, h=0.05), 200, File,
                 "export npz")
    z = np.load(io.BytesIO(npz.payload.read()))
    points = doc["lpv"]["points"]
    if not np.array_equal(z["A"], np.array([p["a"] for p in points])):
        fail("npz A differs from the model's")
    if not np.array_equal(z["Ad"], np.array([p.phi for p in view.discrete.points])):
        fail("npz A_d differs from the service's ZOH")
    if list(z["state_names"]) != ["u", "v", "w", "p", "q", "r"]:
        fail(f"npz state names {list(z['state_names'])}")
    ok("npz export holds the model's A and the service's ZOH A_d")
    print(f"{steps} passed, 0 failed")


if __name__ == "__main__":
    main()
