# astralis-des: the simulator and its CLI in a container.
#
#   docker build -t astralis-des .
#   docker run --rm -v "$PWD/out:/out" astralis-des run missions/urban_search.yaml --out /out/run
#
# Build arguments:
#   BASE    the base image (default python:3.11-slim). A Debian bookworm image without Python
#           works too: python3 and its venv module are then installed with apt-get.
#   EXTRAS  extras of the package to install, comma-separated (default mcap, for
#           `astralis run --mcap`), e.g. EXTRAS=mcap,ray for
#           `astralis study ... --backend ray --address ADDRESS`.
# Where pip needs a CA bundle of the build host, mount its certificates at /hostcerts, e.g.
#   podman --runtime runc build --network host -v /etc/ssl/certs:/hostcerts:ro \
#       --build-arg BASE=localhost/debian-bookworm -t astralis-des .
# /hostcerts/ca-certificates.crt is used only when it is there.
ARG BASE=python:3.11-slim
FROM ${BASE} AS python

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PIP_NO_CACHE_DIR=1 \
    VIRTUAL_ENV=/opt/venv \
    PATH=/opt/venv/bin:$PATH

# Python where the base has none (plain Debian); the wheels need nothing else from the system
# (pybullet, ompl, pyarrow, rerun bundle their libraries; zlib is in every Debian base).
RUN set -eux; \
    if ! command -v python3 >/dev/null 2>&1 || ! python3 -c 'import venv, ensurepip' 2>/dev/null; then \
        apt-get update; \
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
            python3 python3-venv python3-pip; \
        apt-get clean; \
        rm -rf /var/lib/apt/lists/* /var/cache/apt/archives/*; \
    fi; \
    python3 -m venv /opt/venv; \
    python3 --version

# The dependencies, read from pyproject.toml in a stage of their own: the layer that installs
# them is cached while the list is the same, whatever else changes (sources, README, tool
# settings in pyproject.toml).
FROM python AS requirements
ARG EXTRAS="mcap"
COPY pyproject.toml /src/pyproject.toml
RUN python3 -c 'import sys, tomllib; p = tomllib.load(open("/src/pyproject.toml", "rb"))["project"]; \
extras = [e.strip() for e in sys.argv[1].split(",") if e.strip()]; \
print("\n".join(p["dependencies"] + [d for e in extras for d in p["optional-dependencies"][e]]))' \
        "${EXTRAS}" > /requirements.txt

FROM python
ARG EXTRAS="mcap"
COPY --from=requirements /requirements.txt /tmp/requirements.txt
RUN set -eux; \
    if [ -f /hostcerts/ca-certificates.crt ]; then export PIP_CERT=/hostcerts/ca-certificates.crt; fi; \
    pip install --no-cache-dir --upgrade pip; \
    pip install --no-cache-dir -r /tmp/requirements.txt; \
    rm /tmp/requirements.txt

# The package itself, non-editable (its data files come with it: see package-data in
# pyproject.toml); the sources are not kept.
COPY pyproject.toml README.md /src/
COPY astralis_des /src/astralis_des
RUN set -eux; \
    if [ -f /hostcerts/ca-certificates.crt ]; then export PIP_CERT=/hostcerts/ca-certificates.crt; fi; \
    if [ -n "${EXTRAS}" ]; then spec="/src[${EXTRAS}]"; else spec=/src; fi; \
    pip install --no-cache-dir "$spec"; \
    pip check; \
    rm -rf /src /tmp/*; \
    astralis --version

# The repository's missions, worlds, studies and tunes, as relative paths resolve in them.
WORKDIR /work
COPY missions ./missions
COPY worlds ./worlds
COPY studies ./studies
COPY tunes ./tunes

ENTRYPOINT ["astralis"]
CMD ["run", "missions/urban_search.yaml"]
