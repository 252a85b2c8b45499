// The API as the page reads it: its address, and its refusals as one readable line.

// Relative, so the page works at / and behind a proxy under a prefix.
export const API = "api/v1";

// A refusal's detail as one readable line (a 422 lists its fields), as client.describe().
export function describe(detail) {
  if (Array.isArray(detail)) {
    return detail.map((e) => {
      const loc = (e.loc || []).filter((p) => p !== "body").join(".");
      return loc ? `${loc}: ${e.msg}` : String(e.msg);
    }).join("; ");
  }
  return typeof detail === "string" ? detail : JSON.stringify(detail);
}
export function refusal(status, body) {
  const why = describe(body.detail ?? body);
  if (status === 409) return `Refused while ${body.state || "busy"}: ${why}`;
  if (status === 422) return `Invalid input: ${why}`;
  if (status === 401) return `Not in control: ${why}`;
  return `Error ${status}: ${why}`;
}
