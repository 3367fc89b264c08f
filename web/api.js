// Thin client of the seatrial HTTP API (see /openapi.yaml).
// Every non-2xx answer becomes an ApiError carrying the server's
// ErrorBody: {status, message, field?, limit?}.

export class ApiError extends Error {
  constructor(body, status) {
    super(body && body.message ? body.message : `HTTP ${status}`);
    this.name = 'ApiError';
    this.status = (body && body.status) || status;
    this.field = body && body.field != null ? body.field : null;
    this.limit = body && body.limit != null ? body.limit : null;
  }
}

async function request(method, path, body, rawBody) {
  const init = { method, headers: { accept: 'application/json' } };
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
  experiment: (id, eid) => request('GET', urls.experimentJson(id, eid)),
};

export const urls = {
  experimentJson: (id, eid) => `/api/campaigns/${enc(id)}/plan/experiments/${enc(eid)}`,
  scheduleCsv: (id, eid) => `/api/campaigns/${enc(id)}/plan/experiments/${enc(eid)}/schedule.csv`,
  runSheet: (id) => `/api/campaigns/${enc(id)}/plan/runsheet`,
  planJson: (id) => `/api/campaigns/${enc(id)}/plan`,
};
