-- wrk: POST {"preset":"fig4a"} to the URL given (its query picks the format).
wrk.method = "POST"
wrk.body = '{"preset":"fig4a"}'
wrk.headers["Content-Type"] = "application/json"
