// Latency trace of dragging, for the browser benchmark (off unless a test turns it on through
// window.dermisEditor.trace.on = true): pointer moves, edit acknowledgements (when the edit was
// sent, and answered — taken before the answer is applied, so a frame it causes is wanted after)
// and frames (when wanted, and on screen), all performance.now() ms.

export const trace = { on: false, moves: [], acks: [], frames: [] };

export function clearTrace() {
  trace.moves.length = 0;
  trace.acks.length = 0;
  trace.frames.length = 0;
}
