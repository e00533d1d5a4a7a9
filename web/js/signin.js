// Sign-in dialog: when the server wants a token (serve --token), the API client's first 401 opens
// this form; the token goes once to POST /session, which sets an HttpOnly session cookie that
// every later request (frames and events too) carries. The page keeps the token nowhere.

import { API } from "./api.js";

let signingIn = null;
const $ = (id) => document.getElementById(id);

/// Resolves once a session exists (one form for every request that met a 401).
export function signIn() {
  if (signingIn) return signingIn;
  signingIn = new Promise((resolve) => {
    const box = $("signin"), form = $("signinForm"), input = $("token"), error = $("signinError");
    error.textContent = "";
    box.hidden = false;
    input.focus();
    form.onsubmit = async (e) => {
      e.preventDefault();
      const body = JSON.stringify({ token: input.value });
      input.value = "";
      error.textContent = "";
      try {
        const r = await fetch(API + "/session", { method: "POST", headers: { "Content-Type": "application/json" }, body });
        if (r.ok) {
          box.hidden = true;
          form.onsubmit = null;
          signingIn = null;
          resolve();
          return;
        }
        const answer = await r.json().catch(() => ({}));
        error.textContent = r.status === 401 ? "That token is not the right one. Try again?"
                                             : (answer.error ? answer.error.message : r.statusText);
      } catch (err) { error.textContent = err.message; }
      input.focus();
    };
  });
  return signingIn;
}
