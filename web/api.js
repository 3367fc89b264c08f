// Thin client of the seatrial HTTP API (see /openapi.yaml).
// Every non-2xx answer becomes an ApiError carrying the server's
// ErrorBody: {status, message, field?, limit?, line?, column?, run_id?}.

export class ApiError extends Error {
  constructor(body, status) {
    super(body && body.message ? body.message : `HTTP ${status}`);
    this.name = 'ApiError';
    this.status = (body && body.status) || status;
    this.field = body && body.field != null ? body.field : null;
    this.limit = body && body.limit != null ? body.limit : null;
    // Uploads: where in which file, and the run the rejected bytes were kept as.
    this.line = body && body.line != null ? body.line : null;
    this.column = body && body.column != null ? body.column : null;
    this.runId = body && body.run_id != null ? body.run_id : null;
  }
}

async function request(method, path, body, rawBody) {
  // The CSRF header every write with the session cookie must carry (see README).
  const init = { method, headers: { accept: 'application/json', 'x-seatrial-csrf': '1' } };
  if (body !== undefined || rawBody !== undefined) {
    init.headers['content-type'] = 'application/json';
    init.body = rawBody !== undefined ? rawBody : JSON.stringify(body);
  }
  let res;
  try {
    res = await fetch(path, init);
  } catch (e) {
    throw new ApiError({ status: 0, message: `network error: ${e.message}` }, 0);
  }
  const text = await res.text();
  let data = null;
  if (text) {
    try { data = JSON.parse(text); } catch { data = null; }
  }
  if (!res.ok) throw new ApiError(data || { message: text || res.statusText }, res.status);
  return data;
}

const enc = encodeURIComponent;

// The API nests a Vessel's profile under `profile` and a Campaign's spec under
// `spec` (see openapi.yaml); the views work on one flat object.
export function flatVessel(v) {
  if (!v || typeof v.profile !== 'object' || v.profile === null) return v;
  const { profile, ...rest } = v;
  return { ...profile, ...rest };
}
export function flatCampaign(c) {
  if (!c || typeof c.spec !== 'object' || c.spec === null) return c;
  const { spec, ...rest } = c;
  return { ...spec, ...rest };
}
const many = (f) => (xs) => (Array.isArray(xs) ? xs.map(f) : xs);

export const api = {
  health: () => request('GET', '/api/health'),
  // Accounts: who is signed in (401: nobody, and the service requires it), sign in and out.
  me: () => request('GET', '/api/auth/me'),
  login: (name, password) => request('POST', '/api/auth/login', { name, password }),
  logout: () => request('POST', '/api/auth/logout'),
  changePassword: (current, next) =>
    request('POST', '/api/auth/password', { current_password: current, new_password: next }),
  // Personal API tokens (own), and users (admins).
  tokens: () => request('GET', '/api/auth/tokens'),
  createToken: (body) => request('POST', '/api/auth/tokens', body),
  revokeToken: (id) => request('DELETE', `/api/auth/tokens/${enc(id)}`),
  users: () => request('GET', '/api/users?limit=1000'),
  createUser: (body) => request('POST', '/api/users', body),
  changeUser: (id, change) => request('PATCH', `/api/users/${enc(id)}`, change),
  vessels: () => request('GET', '/api/vessels').then(many(flatVessel)),
  vessel: (id) => request('GET', `/api/vessels/${enc(id)}`).then(flatVessel),
  createVessel: (profile) => request('POST', '/api/vessels', profile).then(flatVessel),
  campaigns: (vesselId) =>
    request('GET', '/api/campaigns' + (vesselId ? `?vessel_id=${enc(vesselId)}` : '')).then(many(flatCampaign)),
  campaign: (id) => request('GET', `/api/campaigns/${enc(id)}`).then(flatCampaign),
  // `raw` lets the caller keep integers beyond 2^53 (seeds) exact.
  createCampaign: (body, raw) => request('POST', '/api/campaigns', body, raw).then(flatCampaign),
  plan: (id) => request('GET', `/api/campaigns/${enc(id)}/plan`),
  generatePlan: (id) => request('POST', `/api/campaigns/${enc(id)}/plan`),
  // Re-plan with changed campaign settings (families, repetitions, excitation, durations, …).
  replan: (id, changes) => request('POST', `/api/campaigns/${enc(id)}/plan`, changes),
  experiment: (id, eid) => request('GET', urls.experimentJson(id, eid)),
  runs: (id) => request('GET', `/api/campaigns/${enc(id)}/runs`),
  run: (rid) => request('GET', `/api/runs/${enc(rid)}`),
  // What a run is: fields absent are kept, null clears a user value.
  describeRun: (rid, body) => request('PATCH', `/api/runs/${enc(rid)}`, body),
  // Delete a run (409 names the models built from it).
  deleteRun: (rid, reason) => request('DELETE', `/api/runs/${enc(rid)}${reason ? `?reason=${enc(reason)}` : ''}`),
  restoreRun: (rid) => request('POST', `/api/runs/${enc(rid)}/restore`),
  deletedRuns: (id) => request('GET', `/api/campaigns/${enc(id)}/runs?deleted=true`),
  renameRun: (rid, name) => request('PATCH', `/api/runs/${enc(rid)}`, { name }),
  renameVessel: (id, name) => request('PATCH', `/api/vessels/${enc(id)}`, { name }).then(flatVessel),
  // Soft deletes of vessels and campaigns (an optional reason), their undo and the deleted lists.
  deleteVessel: (id, reason) => request('DELETE', `/api/vessels/${enc(id)}${reason ? `?reason=${enc(reason)}` : ''}`).then(flatVessel),
  restoreVessel: (id) => request('POST', `/api/vessels/${enc(id)}/restore`).then(flatVessel),
  deletedVessels: () => request('GET', '/api/vessels?deleted=true').then(many(flatVessel)),
  deleteCampaign: (id, reason) => request('DELETE', `/api/campaigns/${enc(id)}${reason ? `?reason=${enc(reason)}` : ''}`).then(flatCampaign),
  restoreCampaign: (id) => request('POST', `/api/campaigns/${enc(id)}/restore`).then(flatCampaign),
  deletedCampaigns: () => request('GET', '/api/campaigns?deleted=true').then(many(flatCampaign)),
  renameCampaign: (id, name) => request('PATCH', `/api/campaigns/${enc(id)}`, { name }).then(flatCampaign),
  quality: (rid) => request('GET', urls.quality(rid)),
  // Every channel of a run over a window (`query`: from_s, to_s, points), with the window's statistics.
  runTraces: (rid, query) => request('GET', `/api/runs/${enc(rid)}/traces${query ? `?${query}` : ''}`),
  coverage: (id) => request('GET', `/api/campaigns/${enc(id)}/coverage`),
  // The newest predicted precision of the campaign's plan (404 before the first `precision` job).
  precision: (id) => request('GET', `/api/campaigns/${enc(id)}/precision`),
  // The newest experiment design of the campaign (404 before the first `design` job).
  design: (id) => request('GET', `/api/campaigns/${enc(id)}/design`),
  // The newest next-dive proposal (404 before the first `next_dive` job).
  nextDive: (id) => request('GET', `/api/campaigns/${enc(id)}/next-dive`),
  nextDiveSheetUrl: (id) => `/api/campaigns/${enc(id)}/next-dive/runsheet`,
  // Clock offsets of two-file runs (s; null clears the one set by hand).
  campaignClockOffset: (id) => request('GET', `/api/campaigns/${enc(id)}/clock-offset`),
  setCampaignClockOffset: (id, s) => request('PUT', `/api/campaigns/${enc(id)}/clock-offset`, { clock_offset_s: s }),
  setRunClockOffset: (rid, s) => request('PUT', `/api/runs/${enc(rid)}/clock-offset`, { clock_offset_s: s }),
  // Background jobs (identification, discovery) and the models they store.
  jobs: (campaignId) => request('GET', `/api/jobs${campaignId ? `?campaign_id=${enc(campaignId)}` : ''}`),
  job: (jid) => request('GET', `/api/jobs/${enc(jid)}`),
  submitJob: (body) => request('POST', '/api/jobs', body),
  cancelJob: (jid) => request('POST', `/api/jobs/${enc(jid)}/cancel`),
  retryJob: (jid) => request('POST', `/api/jobs/${enc(jid)}/retry`),
  models: (campaignId) => request('GET', `/api/models${campaignId ? `?campaign_id=${enc(campaignId)}` : ''}`),
  lineage: (lineageId) => request('GET', `/api/models?lineage_id=${enc(lineageId)}`),
  // `hSample`: add the ZOH-discretized Φ, Γ at this sample time.
  model: (mid, hSample) => request('GET', `/api/models/${enc(mid)}${hSample != null ? `?h=${enc(hSample)}` : ''}`),
  // Delete a model version; `cascade` also the versions derived from it (else 409 names them).
  // Linear responses of a model for its plots.
  frequencyResponse: (mid, runId) => request('GET', `/api/models/${enc(mid)}/frequency-response${runId ? `?run_id=${enc(runId)}` : ''}`),
  poles: (mid) => request('GET', `/api/models/${enc(mid)}/poles`),
  stepResponse: (mid, kind) => request('GET', `/api/models/${enc(mid)}/step-response?kind=${enc(kind || 'step')}`),
  hankel: (mid) => request('GET', `/api/models/${enc(mid)}/hankel`),
  // Several models validated on one run (`ids`: 1–6 model ids).
  // `win`: {from_s, to_s} validates on that window of the run only.
  compare: (ids, runId, win) => request('GET', `/api/models/compare?a=${enc(ids[0])}&b=${enc(ids[1] || ids[0])}${ids.length > 2 ? `&more=${enc(ids.slice(2).join(','))}` : ''}&run_id=${enc(runId)}${win && win.from_s != null ? `&from_s=${enc(win.from_s)}` : ''}${win && win.to_s != null ? `&to_s=${enc(win.to_s)}` : ''}`),
  deleteModel: (mid, cascade, reason) => request('DELETE', `/api/models/${enc(mid)}?cascade=${cascade ? 'true' : 'false'}${reason ? `&reason=${enc(reason)}` : ''}`),
  restoreModel: (mid) => request('POST', `/api/models/${enc(mid)}/restore`),
  deletedModels: (campaignId) => request('GET', `/api/models?deleted=true&campaign_id=${enc(campaignId)}`),
  renameModel: (mid, name) => request('PATCH', `/api/models/${enc(mid)}`, { name }),
  // Missing-physics discovery reports.
  discrepancies: (mid) => request('GET', `/api/models/${enc(mid)}/discrepancies`),
  discrepancy: (did) => request('GET', `/api/discrepancies/${enc(did)}`),
};

/**
 * Upload a run (multipart/form-data) with XMLHttpRequest, the only browser
 * API that reports upload progress. `files` is {file} or {control, nav}
 * (File/Blob), `meta` the JSON meta part (omitted when empty).
 *   onProgress(loaded, total)  while the bytes go out
 *   onSent()                   all bytes sent; the server now parses and scores
 * Resolves with the Run (201); rejects with an ApiError (422: field = file,
 * line, column, runId). Returns {promise, abort}.
 */
export function uploadRun(id, { files, meta }, { onProgress, onSent } = {}) {
  const form = new FormData();
  if (meta && Object.keys(meta).length) form.append('meta', JSON.stringify(meta));
  for (const role of ['file', 'control', 'nav']) {
    const f = files[role];
    if (f) form.append(role, f, f.name || `${role}.csv`);
  }
  const xhr = new XMLHttpRequest();
  const promise = new Promise((resolve, reject) => {
    let sent = false;
    const markSent = () => {
      if (sent) return;
      sent = true;
      if (onSent) onSent();
    };
    xhr.upload.addEventListener('progress', (e) => {
      if (onProgress) onProgress(e.loaded, e.lengthComputable ? e.total : null);
      if (e.lengthComputable && e.loaded >= e.total) markSent();
    });
    xhr.upload.addEventListener('load', markSent);
    xhr.addEventListener('load', () => {
      markSent();
      let data = null;
      try { data = xhr.responseText ? JSON.parse(xhr.responseText) : null; } catch { data = null; }
      if (xhr.status >= 200 && xhr.status < 300) resolve(data);
      else reject(new ApiError(data || { message: xhr.responseText || xhr.statusText }, xhr.status));
    });
    xhr.addEventListener('error', () => reject(new ApiError({ status: 0, message: 'network error: the upload did not reach the server' }, 0)));
    xhr.addEventListener('abort', () => reject(new ApiError({ status: 0, message: 'upload cancelled' }, 0)));
    xhr.open('POST', `/api/campaigns/${enc(id)}/runs`);
    xhr.setRequestHeader('accept', 'application/json');
    xhr.setRequestHeader('x-seatrial-csrf', '1');
    xhr.send(form);
  });
  return { promise, abort: () => xhr.abort() };
}

export const urls = {
  experimentJson: (id, eid) => `/api/campaigns/${enc(id)}/plan/experiments/${enc(eid)}`,
  scheduleCsv: (id, eid) => `/api/campaigns/${enc(id)}/plan/experiments/${enc(eid)}/schedule.csv`,
  runSheet: (id) => `/api/campaigns/${enc(id)}/plan/runsheet`,
  planJson: (id) => `/api/campaigns/${enc(id)}/plan`,
  // Raw bytes of a run: `file` (single-file run, the default), `control` or `nav`.
  raw: (rid, role) => `/api/runs/${enc(rid)}/raw${role && role !== 'file' ? `?file=${enc(role)}` : ''}`,
  quality: (rid) => `/api/runs/${enc(rid)}/quality`,
  run: (rid) => `#/runs/${enc(rid)}`,
  model: (mid) => `#/models/${enc(mid)}`,
  discrepancy: (did) => `#/discrepancies/${enc(did)}`,
  jobEvents: (jid) => `/api/jobs/${enc(jid)}/events`,
  modelExport: (mid, format) => `/api/models/${enc(mid)}/export?format=${enc(format)}`,
};
