#!/usr/bin/env bash
# make-pki.sh: the DDS Security material of a dynid deployment (docs/SECURITY.md).
#
# Creates, in OUT:
#   ca/ca_cert.pem, ca/ca_key.pem      one CA, used as identity CA and as permissions CA
#   governance.xml, governance.p7s     domain and topic rules (signed by the CA)
#   <role>-<name>/cert.pem, key.pem    an identity per subject (role: server, car, engineer)
#   <role>-<name>/permissions.xml/.p7s that subject's grant (signed by the CA)
#   <role>-<name>/cyclonedds.xml       the network configuration plus the Security section,
#                                      for --cyclone-config of dynid-server, dynid-car, dynid
# Rerunning with an OUT that holds a CA enrols further subjects with that CA (the governance is
# kept); a subject that exists already is refused. Nothing is written unless every argument is
# valid, and a failure part way leaves OUT as it was (subjects are made in a staging folder).
#
# Rules (permissions, default DENY):
#   server    subscribes RunAnnouncement, Chunk in vehicle/*; publishes ChunkAck, Estimate in
#             vehicle/*; subscribes Request, publishes Reply in the default partition
#   car X     publishes RunAnnouncement, Chunk and subscribes ChunkAck, in vehicle/X only
#   engineer  subscribes Estimate in vehicle/* and Reply, publishes Request (default partition)
set -euo pipefail

usage() {
  cat <<'EOF'
usage: make-pki.sh --out DIR [--server NAME]... [--car ID]... [--engineer NAME]...
                   [--days N] [--network-config FILE] [--plugin-dir DIR] [--domains MIN-MAX]

  --out DIR             output folder (created; an existing CA in it is reused to enrol)
  --server NAME         a server identity (repeat for shards), e.g. --server main
  --car ID              a car identity for vehicle ID (its partition vehicle/ID)
  --engineer NAME       an engineer identity
  --days N              validity of new certificates and permissions, from now (default 3650)
  --network-config F    Cyclone configuration the Security section is added to
                        (default: deploy/cyclonedds/loopback.xml beside this script)
  --plugin-dir DIR      folder of libdds_security_{auth,ac,crypto}.so
                        (default: found under /usr/lib, Debian's libddsc0debian)
  --domains MIN-MAX     DDS domain ids the governance and grants cover (default 0-230)

Names and ids: 1 to 64 characters of A-Z a-z 0-9 . _ - (they become certificate subjects,
partition names and folder names).
EOF
}

die() { echo "make-pki.sh: $*" >&2; exit 1; }

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="" days=3650 network="$here/../cyclonedds/loopback.xml" plugin_dir="" domains="0-230"
servers=() cars=() engineers=()

need_value() { [[ $# -ge 2 && -n "$2" ]] || die "$1 needs a value (see --help)"; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) need_value "$@"; out="$2"; shift 2 ;;
    --server) need_value "$@"; servers+=("$2"); shift 2 ;;
    --car) need_value "$@"; cars+=("$2"); shift 2 ;;
    --engineer) need_value "$@"; engineers+=("$2"); shift 2 ;;
    --days) need_value "$@"; days="$2"; shift 2 ;;
    --network-config) need_value "$@"; network="$2"; shift 2 ;;
    --plugin-dir) need_value "$@"; plugin_dir="$2"; shift 2 ;;
    --domains) need_value "$@"; domains="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument '$1'" ;;
  esac
done

# ---- validation: everything before the first write ------------------------------------------

[[ -n "$out" ]] || { usage >&2; die "--out is required"; }
[[ ! -e "$out" || -d "$out" ]] || die "--out '$out' exists and is not a folder"
(( ${#servers[@]} + ${#cars[@]} + ${#engineers[@]} > 0 )) ||
  die "no subject given: name at least one --server, --car or --engineer"
[[ "$days" =~ ^[1-9][0-9]{0,5}$ ]] || die "--days '$days': a whole number of days, 1 to 999999"
[[ "$domains" =~ ^([0-9]+)-([0-9]+)$ ]] || die "--domains '$domains': MIN-MAX, e.g. 0-230"
domain_min="${BASH_REMATCH[1]}" domain_max="${BASH_REMATCH[2]}"
(( domain_min <= domain_max && domain_max <= 232 )) ||
  die "--domains '$domains': need MIN <= MAX <= 232"
[[ -f "$network" ]] || die "--network-config '$network': no such file"
grep -q '</Domain>' "$network" || die "--network-config '$network': no </Domain> element to extend"
command -v openssl >/dev/null || die "openssl is not installed (apt-get install openssl)"

if [[ -z "$plugin_dir" ]]; then
  for d in /usr/lib/*/libddsc0debian /usr/lib/libddsc0debian /usr/lib/*/ /usr/local/lib; do
    if [[ -f "$d/libdds_security_auth.so" ]]; then plugin_dir="${d%/}"; break; fi
  done
  [[ -n "$plugin_dir" ]] || die "libdds_security_auth.so not found under /usr/lib: pass --plugin-dir"
fi
for lib in auth ac crypto; do
  [[ -f "$plugin_dir/libdds_security_$lib.so" ]] ||
    die "--plugin-dir '$plugin_dir': libdds_security_$lib.so missing"
done
plugin_dir="$(cd "$plugin_dir" && pwd)"

declare -A seen=()
check_name() {  # role name
  [[ "$2" =~ ^[A-Za-z0-9._-]{1,64}$ ]] ||
    die "--$1 '$2': use 1 to 64 characters of A-Z a-z 0-9 . _ -"
  [[ -z "${seen[$1-$2]:-}" ]] || die "--$1 '$2' given twice"
  seen[$1-$2]=1
  [[ ! -e "$out/$1-$2" ]] || die "$1 '$2' is already enrolled in $out/$1-$2 (remove it to re-issue)"
}
for n in "${servers[@]}"; do check_name server "$n"; done
for n in "${cars[@]}"; do check_name car "$n"; done
for n in "${engineers[@]}"; do check_name engineer "$n"; done
if [[ -e "$out/ca" ]]; then
  [[ -f "$out/ca/ca_cert.pem" && -f "$out/ca/ca_key.pem" && -f "$out/governance.p7s" ]] ||
    die "$out/ca exists but ca_cert.pem, ca_key.pem or ../governance.p7s is missing"
fi

# ---- generation, in a staging folder --------------------------------------------------------

[[ -d "$out" ]] || created_out=1
mkdir -p "$out"
out="$(cd "$out" && pwd)"
stage="$(mktemp -d "$out/.staging-XXXXXX")"
# On any exit: the staging folder goes; an --out made by this run goes too if it stayed empty.
trap 'rm -rf "$stage"; if [[ -n "${created_out:-}" ]]; then rmdir "$out" 2>/dev/null || true; fi' EXIT
umask 077  # private keys; the rest is made readable below

now_s="$(date -u +%s)"
not_before="$(date -u -d "@$now_s" +%Y-%m-%dT%H:%M:%SZ)"
not_after="$(date -u -d "@$((now_s + days * 86400))" +%Y-%m-%dT%H:%M:%SZ)"

quiet() {  # runs openssl, shows its output only when it fails
  local log
  if ! log="$("$@" 2>&1)"; then die "$* failed: $log"; fi
}
new_key() { quiet openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1"; }
sign_document() {  # in out: S/MIME signed by the CA, the signer certificate included
  quiet openssl smime -sign -text -in "$1" -out "$2" -signer "$ca/ca_cert.pem" -inkey "$ca/ca_key.pem"
}

if [[ -e "$out/ca" ]]; then
  ca="$out/ca"
else
  ca="$stage/ca"
  mkdir -p "$ca"
  new_key "$ca/ca_key.pem"
  quiet openssl req -x509 -new -key "$ca/ca_key.pem" -out "$ca/ca_cert.pem" -days "$days" \
    -subj "/O=dynid/CN=dynid CA" -addext "basicConstraints=critical,CA:TRUE" \
    -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature"
  cat >"$stage/governance.xml" <<EOF
<?xml version="1.0" encoding="utf-8"?>
<!-- dynid governance (docs/SECURITY.md): only authenticated participants join; discovery,
     liveliness and every dynid topic's data are encrypted; creating a reader or writer of any
     topic needs a grant in the participant's signed permissions. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="https://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>$domain_min</min><max>$domain_max</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>SIGN</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
  sign_document "$stage/governance.xml" "$stage/governance.p7s"
fi

# criteria KIND PARTITION TOPIC...: a <publish> or <subscribe> block ("" = default partition)
criteria() {
  local kind="$1" partition="$2"; shift 2
  echo "        <$kind>"
  echo "          <topics>"
  for t in "$@"; do echo "            <topic>$t</topic>"; done
  echo "          </topics>"
  echo "          <partitions><partition>$partition</partition></partitions>"
  echo "        </$kind>"
}

grants_of() {  # role name
  case "$1" in
    server)
      criteria subscribe 'vehicle/*' dynid/RunAnnouncement dynid/Chunk
      criteria publish 'vehicle/*' dynid/ChunkAck dynid/Estimate
      criteria subscribe '' dynid/Request
      criteria publish '' dynid/Reply ;;
    car)
      criteria publish "vehicle/$2" dynid/RunAnnouncement dynid/Chunk
      criteria subscribe "vehicle/$2" dynid/ChunkAck ;;
    engineer)
      criteria subscribe 'vehicle/*' dynid/Estimate
      criteria subscribe '' dynid/Reply
      criteria publish '' dynid/Request ;;
  esac
}

write_permissions() {  # role name subject file
  cat >"$4" <<EOF
<?xml version="1.0" encoding="utf-8"?>
<!-- dynid permissions of $1 '$2' (docs/SECURITY.md) -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="https://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$1-$2">
      <subject_name>$3</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>$domain_min</min><max>$domain_max</max></id_range></domains>
$(grants_of "$1" "$2")
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
EOF
}

write_config() {  # dir: the network configuration with the Security section before </Domain>
  local dir="$1" final="$out/$(basename "$1")" section
  section="$(cat <<EOF
    <Security>
      <Authentication>
        <Library path="$plugin_dir/libdds_security_auth.so" initFunction="init_authentication" finalizeFunction="finalize_authentication"/>
        <IdentityCA>file:$out/ca/ca_cert.pem</IdentityCA>
        <IdentityCertificate>file:$final/cert.pem</IdentityCertificate>
        <PrivateKey>file:$final/key.pem</PrivateKey>
      </Authentication>
      <AccessControl>
        <Library path="$plugin_dir/libdds_security_ac.so" initFunction="init_access_control" finalizeFunction="finalize_access_control"/>
        <PermissionsCA>file:$out/ca/ca_cert.pem</PermissionsCA>
        <Governance>file:$out/governance.p7s</Governance>
        <Permissions>file:$final/permissions.p7s</Permissions>
      </AccessControl>
      <Cryptographic>
        <Library path="$plugin_dir/libdds_security_crypto.so" initFunction="init_crypto" finalizeFunction="finalize_crypto"/>
      </Cryptographic>
    </Security>
EOF
)"
  # Insert before the first </Domain>; awk keeps the rest of the file as it is.
  SECTION="$section" awk '!done && /<\/Domain>/ { print ENVIRON["SECTION"]; done = 1 } { print }' \
    "$network" >"$dir/cyclonedds.xml"
}

make_subject() {  # role name
  local role="$1" name="$2" dir="$stage/$1-$2" subject
  mkdir -p "$dir"
  new_key "$dir/key.pem"
  quiet openssl req -new -key "$dir/key.pem" -out "$dir/cert.csr" -subj "/O=dynid/OU=$role/CN=$name"
  quiet openssl x509 -req -in "$dir/cert.csr" -CA "$ca/ca_cert.pem" -CAkey "$ca/ca_key.pem" \
    -CAcreateserial -CAserial "$stage/ca.srl" -days "$days" -out "$dir/cert.pem"
  rm -f "$dir/cert.csr"
  subject="$(openssl x509 -noout -subject -nameopt RFC2253 -in "$dir/cert.pem")"
  subject="${subject#subject=}"
  write_permissions "$role" "$name" "$subject" "$dir/permissions.xml"
  sign_document "$dir/permissions.xml" "$dir/permissions.p7s"
  write_config "$dir"
  chmod 644 "$dir"/cert.pem "$dir"/permissions.* "$dir"/cyclonedds.xml
  chmod 755 "$dir"
}

for n in "${servers[@]}"; do make_subject server "$n"; done
for n in "${cars[@]}"; do make_subject car "$n"; done
for n in "${engineers[@]}"; do make_subject engineer "$n"; done

# ---- into place ----------------------------------------------------------------------------
rm -f "$stage/ca.srl"
if [[ "$ca" == "$stage/ca" ]]; then
  chmod 644 "$ca/ca_cert.pem" "$stage"/governance.*
  chmod 755 "$ca"
  mv "$ca" "$stage/governance.xml" "$stage/governance.p7s" "$out/"
fi
made=()
for d in "$stage"/*-*; do
  [[ -d "$d" ]] || continue
  mv "$d" "$out/"
  made+=("$out/$(basename "$d")")
done
echo "make-pki.sh: CA $out/ca; valid until $not_after; subjects:"
printf '  %s\n' "${made[@]}"
