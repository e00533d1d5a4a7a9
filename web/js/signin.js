// Sign-in dialog: when the server wants a token (serve --token), the API client's first 401 opens
// this form; the token goes once to POST /session, which sets an HttpOnly session cookie that
// every later request (frames and events too) carries. The page keeps the token nowhere.

import { openSession } from "./api.js";

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
      const token = input.value;
      input.value = "";
      error.textContent = "";
      try {
        await openSession(token);
        box.hidden = true;
        form.onsubmit = null;
        signingIn = null;
        resolve();
        return;
      } catch (err) {
        error.textContent = err.status === 401 ? "That token is not the right one. Try again?" : (err.raw ?? err.message);
      }
      input.focus();
    };
  });
  return signingIn;
}
