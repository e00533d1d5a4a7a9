// API client of the Dermis editor: every request to /api/v1 goes through here. It names this
// editor (X-Dermis-Client), sends If-Match when the caller gives a revision, turns error answers
// into ApiError (code, message, field, status, and the current revision of a 412), and asks the
// sign-in dialog for a session when the server answers 401 (then retries once). It keeps no token:
// the session lives in the server's HttpOnly cookie (openSession opens it). Does not cache and does
// not retry otherwise.

import { inWords } from "./messages.js";

export const API = "/api/v1";

/// An error answer of the server (or a network failure: status 0, code "network"). `message` is
/// in words for people (messages.js); `raw` is the server's own message.
export class ApiError extends Error {
  constructor(status, code, message, field = "", revision = undefined) {
    super(inWords({ message, code, field }));
    this.raw = message;
    this.status = status;
    this.code = code;
    this.field = field;
    this.revision = revision;
  }
}

/// A short random name of this editor window, shown to other people (history, presence).
export function makeClientName() {
  const adjectives = ["amber", "brisk", "calm", "deft", "eager", "fleet", "keen", "lucid", "merry", "nimble"];
  const nouns = ["heron", "lynx", "otter", "finch", "marten", "wren", "ibex", "koi", "puma", "stoat"];
  const pick = (a) => a[Math.floor(Math.random() * a.length)];
  return `${pick(adjectives)}-${pick(nouns)}-${Math.random().toString(36).slice(2, 6)}`;
}

export class Api {
  /// signIn: async () => void, shows the sign-in form and resolves once a session exists.
  constructor({ client, signIn }) {
    this.client = client;
    this.signIn = signIn;
    this.signIns = 0;
  }

  /// fetch() of `path` under /api/v1 with this client's headers; signs in once on 401.
  async raw(method, path, { body, ifMatch, headers = {}, signal } = {}) {
    const h = { "X-Dermis-Client": this.client, ...headers };
    if (ifMatch !== undefined && ifMatch !== null) h["If-Match"] = `"r${ifMatch}"`;
    let payload = body;
    if (body !== undefined && !(body instanceof Blob) && !(body instanceof ArrayBuffer) && !(body instanceof FormData)) {
      h["Content-Type"] = "application/json";
      payload = JSON.stringify(body);
    }
    const go = () => fetch(API + path, { method, headers: h, body: payload, signal });
    let r;
    try {
      r = await go();
      if (r.status === 401 && this.signIn) {
        await this.signIn();
        ++this.signIns;
        r = await go();
      }
    } catch (e) {
      if (e.name === "AbortError") throw e;
      throw new ApiError(0, "network", `The server cannot be reached (${e.message}).`);
    }
    if (!r.ok) throw await ApiError_from(r);
    return r;
  }

  /// The JSON answer of a request ({} for 204).
  async json(method, path, opts) {
    const r = await this.raw(method, path, opts);
    if (r.status === 204) return {};
    return r.json();
  }

  get(path, opts) { return this.json("GET", path, opts); }
  send(method, path, body, ifMatch) { return this.json(method, path, { body, ifMatch }); }

  /// A Blob answer (images).
  async blob(path, opts) { return (await this.raw("GET", path, opts)).blob(); }
}

/// Opens a session with `token` (POST /session: the server sets its HttpOnly session cookie),
/// for the sign-in dialog. Not through an Api: no client name, and a 401 here means a wrong token,
/// not "sign in". Throws ApiError: 401 for a wrong token, status 0 (code "network", `raw` the
/// browser's words) where the server cannot be reached.
export async function openSession(token) {
  let r;
  try {
    r = await fetch(API + "/session", { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ token }) });
  } catch (e) {
    throw new ApiError(0, "network", e.message);
  }
  if (!r.ok) throw await ApiError_from(r);
}

async function ApiError_from(r) {
  let answer = {};
  try { answer = await r.json(); } catch { /* not JSON */ }
  const e = answer.error || {};
  return new ApiError(r.status, e.code || `http_${r.status}`, e.message || r.statusText || `HTTP ${r.status}`,
                      e.field || "", answer.revision);
}

/// A query string of the defined entries of `params` (numbers rounded to 4 decimals).
export function query(params) {
  const parts = [];
  for (const [k, v] of Object.entries(params)) {
    if (v === undefined || v === null || v === "") continue;
    const s = typeof v === "number" ? String(Math.round(v * 1e4) / 1e4) : String(v);
    parts.push(`${encodeURIComponent(k)}=${encodeURIComponent(s)}`);
  }
  return parts.length ? "?" + parts.join("&") : "";
}
