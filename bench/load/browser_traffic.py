#!/usr/bin/env python3
"""What one browser on dynid-dashboard's fleet view asks, for the load benchmark
(run-load.sh dashboards): the event stream read as it comes, and /api/fleet every 0.3 s (the
page redraws at most that often while estimates come), each on one kept-alive connection, as a
browser holds them. Runs until killed.

    browser_traffic.py PORT TOKEN_FILE
"""
import http.client
import sys
import threading
import time


def events(port, token):
    connection = http.client.HTTPConnection("127.0.0.1", port)
    connection.request("GET", "/events", headers={"Authorization": "Bearer " + token})
    response = connection.getresponse()
    while response.read1(65536):
        pass


def main():
    port, token = int(sys.argv[1]), open(sys.argv[2]).read().strip()
    threading.Thread(target=events, args=(port, token), daemon=True).start()
    connection = http.client.HTTPConnection("127.0.0.1", port)
    while True:
        try:
            connection.request("GET", "/api/fleet", headers={"Authorization": "Bearer " + token})
            connection.getresponse().read()
        except (OSError, http.client.HTTPException):
            connection.close()
            connection = http.client.HTTPConnection("127.0.0.1", port)
        time.sleep(0.3)


if __name__ == "__main__":
    main()
