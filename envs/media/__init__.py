"""What a researcher looks at: videos and pictures (render), chronophotographs (chrono), rerun
recordings (record, record_body) and the web viewer's check (viewer_check).
"""
