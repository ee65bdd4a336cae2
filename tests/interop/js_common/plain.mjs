// What Foxglove's CDR decoder gives, as plain JSON for the C++ tests to compare
// (tests/support/foxglove_compare.hpp): 64-bit integers as decimal strings, typed arrays as
// arrays, non-finite floats as null. Shared by mcap_js/read_mcap.mjs and foxglove_js/client.mjs.
export function plain(v) {
  if (typeof v === "bigint") return v.toString();
  if (typeof v === "number") return Number.isFinite(v) ? v : null;
  if (ArrayBuffer.isView(v)) return Array.from(v, plain);
  if (Array.isArray(v)) return v.map(plain);
  if (v !== null && typeof v === "object") {
    const out = {};
    for (const [k, x] of Object.entries(v)) out[k] = plain(x);
    return out;
  }
  return v;
}
